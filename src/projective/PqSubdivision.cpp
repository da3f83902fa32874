#include "projective/PqSubdivision.h"

#include <string>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/Timing.h"
#include "projective/GlobalStep.h"
#include "projective/LocalStep.h"
#include "projective/ShapeSpace.h"

namespace plano::projective {

namespace {

PlanarityStats planarityOf(compute::Backend& backend, const PolygonMesh& mesh, double tolerance) {
  std::vector<double> values(mesh.faceCount());
  backend.facePlanarity(mesh, values);
  return summarizePlanarity(values, tolerance);
}

void checkSettings(const PqSubdivisionSettings& settings) {
  if (settings.levels < 0) throwUsage("subdivision levels must be >= 0 (got " + std::to_string(settings.levels) + ")");
  if (!(settings.planarityTolerance > 0.0)) throwUsage("subdivision: the planarity tolerance must be positive");
  if (!(settings.changeTolerance > 0.0)) throwUsage("subdivision: the change tolerance must be positive");
  if (settings.maxIterationsPerLevel < 1) throwUsage("subdivision: at least one iteration per level is needed");
}

/// The local/global iterations of one level (§5 steps 1-4), from the trivially refined
/// base towards the targets; returns the final positions. The positions (normalized), the
/// fits and the global step's solution stay where the backend computes them: on a device
/// an iteration moves no mesh-sized data (scalars come back).
Positions planarizeLevel(compute::Backend& backend, const PolygonMesh& refined, const Positions& targets,
                         const PqSubdivisionSettings& settings, const PqIterationCallback& callback,
                         PqLevelInfo& info) {
  const ShapeSpace space(refined);
  GlobalStep global(backend, space, {}, settings.globalStep);
  // The change is measured against the targets' diagonal; the positions' displacements come
  // in normalized units (the base's diagonal).
  const double diagonal = boundingBoxDiagonal(targets);
  const double toChange = diagonal > 0.0 ? space.normalization().scale / diagonal : 0.0;
  const compute::VertexCorners corners = space.vertexCorners();
  compute::DeviceMatrix current(Eigen::MatrixXd(normalizedTargetPositions(space, targets)));
  for (int iteration = 0; iteration < settings.maxIterationsPerLevel; ++iteration) {
    throwIfCancelled("subdivision");
    const std::optional<compute::DeviceTransfers> transfersBefore = backend.transfers();
    compute::DeviceProjectiveFits fits;
    compute::DeviceMatrix columns;
    const GlobalStepInfo step = global.solveProjectiveFitsAt(current, Positions(), fits, columns);
    compute::MapPositions next;
    backend.mapPositions(space.faces(), space.basePositions(), corners, columns, fits.reciprocalScales, current, next);
    current = std::move(next.positions);

    PqIteration record;
    record.epsilon = step.epsilon;
    record.constraintResidual = step.constraintResidual;
    record.admmIterations = step.admmIterations;
    record.linearIterations = step.linearIterations;
    record.attempts = step.attempts;
    record.maxPlanarity = next.maxPlanarity;
    record.maxChange = next.displacement * toChange;
    record.transfers = compute::transfersSince(transfersBefore, backend.transfers());
    info.iterations.push_back(record);
    if (callback) callback(info.level, iteration + 1, info.iterations.back());
    if (record.maxPlanarity <= settings.planarityTolerance && record.maxChange <= settings.changeTolerance) {
      info.converged = true;
      break;
    }
  }
  return space.normalization().toWorld(Positions(current.values()));
}

}  // namespace

const char* toString(PqSubdivisionStatus status) {
  switch (status) {
    case PqSubdivisionStatus::Converged: return "converged";
    case PqSubdivisionStatus::IterationLimit: return "iteration_limit";
    case PqSubdivisionStatus::LinearOnly: return "linear_only";
  }
  return "unknown";
}

PqSubdivisionResult subdividePlanarQuads(compute::Backend& backend, const PolygonMesh& base,
                                         const PqSubdivisionSettings& settings, const PqIterationCallback& callback) {
  checkSettings(settings);
  const auto start = SteadyClock::now();
  PqSubdivisionResult result{SubdivisionHierarchy(base.faces, base.vertexCount(), settings.levels), {base.vertices}, {}};
  PqSubdivisionInfo& info = result.info;
  info.status = settings.planarize ? PqSubdivisionStatus::Converged : PqSubdivisionStatus::LinearOnly;

  for (int level = 1; level <= settings.levels; ++level) {
    const auto levelStart = SteadyClock::now();
    const QuadRefinement& refinement = result.hierarchy.refinement(level);
    const FaceList& coarseFaces = result.hierarchy.faces(level - 1);
    const Positions& coarse = result.positions.back();
    const Positions linear = linearSubdivision(settings.scheme, coarseFaces, coarse, refinement);

    PqLevelInfo levelInfo;
    levelInfo.level = level;
    levelInfo.vertices = refinement.fineVertexCount();
    levelInfo.faces = refinement.fineFaces.size();
    levelInfo.linearMaxPlanarity =
        planarityOf(backend, PolygonMesh{linear, refinement.fineFaces}, settings.planarityTolerance).max;

    Positions fine = linear;
    if (settings.planarize) {
      const PolygonMesh refined{trivialRefinementPositions(refinement, coarseFaces, coarse), refinement.fineFaces};
      fine = planarizeLevel(backend, refined, linear, settings, callback, levelInfo);
      if (!levelInfo.converged) info.status = PqSubdivisionStatus::IterationLimit;
    }
    const double diagonal = boundingBoxDiagonal(linear);
    levelInfo.distanceToLinear = diagonal > 0.0 ? maxVertexDistance(fine, linear) / diagonal : 0.0;
    levelInfo.planarity = planarityOf(backend, PolygonMesh{fine, refinement.fineFaces}, settings.planarityTolerance);
    levelInfo.seconds = secondsSince(levelStart);
    info.totalIterations += static_cast<int>(levelInfo.iterations.size());
    info.levels.push_back(std::move(levelInfo));
    result.positions.push_back(std::move(fine));
  }
  info.seconds = secondsSince(start);
  return result;
}

}  // namespace plano::projective
