#include "projective/PqSubdivision.h"

#include <algorithm>
#include <iomanip>
#include <sstream>
#include <string>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/Memory.h"
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

/// An iteration whose max planarity stays above this fraction of the previous one's made
/// little progress: the double torus's refits flatten 0-2 % per iteration from its sixth on,
/// the Enneper hexagons' 6-15 % until their 18th.
constexpr double kRefitStall = 0.95;

void checkSettings(const PqSubdivisionSettings& settings) {
  if (settings.levels < 0) throwUsage("subdivision levels must be >= 0 (got " + std::to_string(settings.levels) + ")");
  if (!(settings.planarityTolerance > 0.0)) throwUsage("subdivision: the planarity tolerance must be positive");
  if (!(settings.changeTolerance > 0.0)) throwUsage("subdivision: the change tolerance must be positive");
  if (settings.maxIterationsPerLevel < 1) throwUsage("subdivision: at least one iteration per level is needed");
  if (settings.intermediateAttempts < 0) throwUsage("subdivision: the intermediate attempts must be >= 0");
}

/// What a subdivision holds per face of its finest level, measured on the cube (2026-12-05,
/// `plano subdivide`'s peak memory): the linear scheme 247 B (11 levels, 25M faces, 6.07 GB:
/// the hierarchy and positions 206 B, the output file's text 41 B), taken as 250; a
/// planarized finest level 4.1 KB (the 98k-face level, which needed no ADMM iteration) to
/// 19 KB (6 levels, 24k faces), of which half the smaller is taken.
constexpr double kLinearBytesPerFinestFace = 250.0;
constexpr double kPlanarizedBytesPerFinestFace = 2048.0;

/// The hierarchy is built for every level at once: refuse levels that cannot fit before
/// any is built. 12 linear levels of the cube (100M faces, ~25 GB) were killed by the
/// kernel after 2 minutes on a 23 GiB machine: Linux grants the allocations and kills the
/// process once it fills them.
void requireMemoryForLevels(const FaceList& base, const PqSubdivisionSettings& settings) {
  if (settings.levels == 0) return;
  double finestFaces = static_cast<double>(base.cornerCount());  // level 1: a quad per corner
  for (int level = 2; level <= settings.levels; ++level) finestFaces *= 4.0;
  std::ostringstream what;
  what << "subdividing " << base.size() << " faces " << settings.levels << " times (" << std::fixed
       << std::setprecision(0) << finestFaces << " faces at the finest level"
       << (settings.planarize ? ", planarized" : "") << ")";
  requireMemory(finestFaces * (settings.planarize ? kPlanarizedBytesPerFinestFace : kLinearBytesPerFinestFace),
                what.str(), settings.memoryLimitBytes);
}

/// Every face of a level is a projective image of its base face, the trivial refinement of
/// its coarse face, and a projective map keeps a non-planar face non-planar: from an input
/// whose refined faces exceed the bound the iterations cannot be expected to reach it (a
/// 5.3 %-non-planar hyperbolic paraboloid grid stayed at 2.65 % for 20 iterations; a
/// 60 %-non-planar control mesh drifted to 90 %). Later levels start from a level's result.
void requirePlanarEnoughBase(compute::Backend& backend, const PolygonMesh& refined, const QuadRefinement& refinement,
                             double tolerance) {
  std::vector<double> values(refined.faceCount());
  backend.facePlanarity(refined, values);
  const auto worst = std::max_element(values.begin(), values.end());
  if (worst == values.end() || *worst <= tolerance) return;
  const auto fine = static_cast<std::size_t>(worst - values.begin());
  const auto over = std::count_if(values.begin(), values.end(), [&](double v) { return v > tolerance; });
  std::ostringstream message;
  message << "subdivision: the input mesh is not planar enough: its refined faces are up to " << *worst
          << " % non-planar (" << over << " of " << values.size() << " above the " << tolerance
          << " % bound; the worst is cut from input face " << refinement.parentFace[fine]
          << "), and every subdivided face is a projective image of one of them. Planarize the mesh first or "
             "raise the planarity tolerance";
  throwBadInput(message.str());
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
    // The step kept its targets after failed attempts, and the refits alone no longer
    // flatten the faces: the rest of the level tries eps between the failed ones and the
    // violation (PqSubdivisionSettings::intermediateAttempts).
    const bool keptTargets = step.status == GlobalStepStatus::Unchanged && step.attempts.size() > 1;
    if (keptTargets && !info.iterations.empty() &&
        record.maxPlanarity > kRefitStall * info.iterations.back().maxPlanarity) {
      global.setIntermediateAttempts(settings.intermediateAttempts);
    }
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
  requireMemoryForLevels(base.faces, settings);
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
      if (level == 1) requirePlanarEnoughBase(backend, refined, refinement, settings.planarityTolerance);
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
