#include "projective/MultiresDeformation.h"

#include <string>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/Timing.h"
#include "projective/Deformation.h"
#include "projective/IdealMaps.h"
#include "projective/LocalStep.h"
#include "projective/MultiresCoarseStep.h"
#include "projective/ShapeSpace.h"

namespace plano::projective {

namespace {

/// (x, 1) M = ((x - centre) / scale, 1): world to normalized coordinates as a 4x4 map in
/// the row-vector convention, and its inverse.
Eigen::Matrix4d toNormalizedMap(const Normalization& n) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() /= n.scale;
  m.block<1, 3>(3, 0) = -n.centre / n.scale;
  return m;
}
Eigen::Matrix4d toWorldMap(const Normalization& n) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() *= n.scale;
  m.block<1, 3>(3, 0) = n.centre;
  return m;
}

/// §6.3: every finest face takes the map of its ancestor on the coarse level, converted
/// from the coarse level's normalized coordinates to the fine level's (same world map).
std::vector<Eigen::Matrix4d> prolongMaps(const std::vector<Eigen::Matrix4d>& coarseMaps, const Normalization& coarse,
                                         const Normalization& fine, const std::vector<Index>& ancestors) {
  const Eigen::Matrix4d into = toWorldMap(fine) * toNormalizedMap(coarse);    // fine normalized -> coarse normalized
  const Eigen::Matrix4d back = toWorldMap(coarse) * toNormalizedMap(fine);    // coarse normalized -> fine normalized
  std::vector<Eigen::Matrix4d> converted(coarseMaps.size());
  for (std::size_t f = 0; f < coarseMaps.size(); ++f) {
    Eigen::Matrix4d m = into * coarseMaps[f] * back;
    m /= m(3, 3);  // keep the normalization A(3, 3) = 1 of the shape space
    converted[f] = m;
  }
  std::vector<Eigen::Matrix4d> prolonged(ancestors.size());
  for (std::size_t g = 0; g < ancestors.size(); ++g) prolonged[g] = converted[ancestors[g]];
  return prolonged;
}

void checkInput(const SubdivisionHierarchy& hierarchy, const std::vector<Positions>& positions,
                const MultiresSettings& settings) {
  const int finest = hierarchy.finestLevel();
  if (static_cast<int>(positions.size()) != finest + 1) {
    throwUsage("multires: " + std::to_string(positions.size()) + " position sets for " + std::to_string(finest + 1) +
               " levels");
  }
  for (int l = 0; l <= finest; ++l) {
    if (positions[l].rows() != hierarchy.vertexCount(l)) {
      throwUsage("multires: level " + std::to_string(l) + " has " + std::to_string(positions[l].rows()) +
                 " positions for " + std::to_string(hierarchy.vertexCount(l)) + " vertices");
    }
  }
  if (settings.level < -1 || settings.level > finest) {
    throwUsage("multires: level " + std::to_string(settings.level) + " is outside the hierarchy (0.." +
               std::to_string(finest) + ", or -1 for the paper's rule)");
  }
  if (settings.maxCoarseIterations < 1) throwUsage("multires: at least one coarse iteration is needed");
  if (!(settings.tolerance > 0.0)) throwUsage("multires: the tolerance must be positive");
}

/// Fixed vertices, then handles: the constrained vertices of the fine global step and
/// their world positions.
void fineConstraints(const PositionalConstraints& constraints, const Positions& finest, std::vector<Index>& vertices,
                     Positions& targets) {
  vertices.clear();
  targets.resize(static_cast<Eigen::Index>(constraints.fixed.size() + constraints.handles.size()), 3);
  for (const Index v : constraints.fixed) {
    targets.row(static_cast<Eigen::Index>(vertices.size())) = finest.row(v);
    vertices.push_back(v);
  }
  for (const Handle& h : constraints.handles) {
    targets.row(static_cast<Eigen::Index>(vertices.size())) = h.position.transpose();
    vertices.push_back(h.vertex);
  }
}

/// Direct single-level deformation of the finest mesh (the rule chose it).
void deformFinest(compute::Backend& backend, const PolygonMesh& mesh, const PositionalConstraints& constraints,
                  const MultiresSettings& settings, const MultiresCallback& callback, MultiresResult& result) {
  DeformationSettings direct;
  direct.energy = settings.energy;
  direct.maxIterations = settings.maxCoarseIterations;
  direct.tolerance = settings.tolerance;
  direct.planarityTolerance = settings.planarityTolerance;
  direct.maxProjectionIterations = settings.maxProjectionIterations;
  direct.global = settings.global;
  direct.global.smoothness = 0.0;
  const auto start = SteadyClock::now();
  int ideal = 0;
  int projection = 0;
  const auto forward = [&](const DeformationIteration& it) {
    if (!callback) return;
    const bool coarse = it.phase == DeformationPhase::Ideal;
    callback({coarse ? MultiresPhase::Coarse : MultiresPhase::Projection, coarse ? ++ideal : ++projection,
              coarse ? it.epsilon : 0.0, coarse ? it.displacement : 0.0, it.maxPlanarity, it.transfers});
  };
  const DeformationResult deformed = deform(backend, mesh, constraints, direct, forward);
  if (deformed.info.status == DeformationStatus::NumericalFailure) throwNumerical("multires: " + deformed.info.message);
  result.positions = deformed.mesh.vertices;
  result.info.coarseIterations = deformed.info.iterations;
  for (const auto& it : deformed.info.history) {
    result.info.coarseEpsilons.push_back(it.epsilon);
    result.info.coarseDisplacements.push_back(it.displacement);
    result.info.coarseTransfers.push_back(it.transfers);
  }
  result.info.coarseSeconds = secondsSince(start);
  if (deformed.info.status != DeformationStatus::Converged) result.info.status = MultiresStatus::MaxIterationsReached;
}

}  // namespace

const char* toString(MultiresStatus status) {
  switch (status) {
    case MultiresStatus::Converged: return "converged";
    case MultiresStatus::MaxIterationsReached: return "max_iterations_reached";
  }
  return "unknown";
}

MultiresResult multiresDeform(compute::Backend& backend, const SubdivisionHierarchy& hierarchy,
                              const std::vector<Positions>& positions, const PositionalConstraints& constraints,
                              const MultiresSettings& settings, const MultiresCallback& callback) {
  checkInput(hierarchy, positions, settings);
  const auto start = SteadyClock::now();
  const int finest = hierarchy.finestLevel();
  MultiresResult result;
  MultiresInfo& info = result.info;
  if (settings.level >= 0) {
    info.level = settings.level;
  } else {
    info.levelChecks = checkDeformationLevels(hierarchy, constraints);
    info.level = chooseDeformationLevel(hierarchy, constraints);
  }
  const int level = info.level;
  const PolygonMesh fineMesh{positions[finest], hierarchy.faces(finest)};
  info.coarseFaces = hierarchy.faces(level).size();
  info.fineFaces = fineMesh.faceCount();

  if (level == finest) {
    deformFinest(backend, fineMesh, constraints, settings, callback, result);
  } else {
    // Coarse deformation (§6.1 on M_k with the coarsened constraints of §6.2).
    const auto coarseStart = SteadyClock::now();
    const CoarseConstraints coarse = coarsenConstraints(hierarchy, positions[finest], constraints, level);
    const ShapeSpace coarseSpace(PolygonMesh{positions[level], hierarchy.faces(level)});
    GlobalStepSettings coarseSettings = settings.global;
    coarseSettings.smoothness = 0.0;
    MultiresCoarseStep coarseStep(backend, coarseSpace, coarse.fixed, coarse.handles, coarseSettings);
    // The coarse positions, normalized, where the backend computes them: on a device the
    // ideal maps, the solution and these positions stay there (scalars come back); the
    // last solution's maps come back once, for the prolongation.
    const compute::VertexCorners coarseCorners = coarseSpace.vertexCorners();
    compute::DeviceMatrix coarseCurrent(Eigen::MatrixXd(normalizedTargetPositions(coarseSpace, positions[level])));
    compute::DeviceMatrix coarseColumns;  // the last solution's first three columns; empty: identity maps
    bool converged = false;
    for (int it = 0; it < settings.maxCoarseIterations && !converged; ++it) {
      throwIfCancelled("multi-resolution deformation");
      const std::optional<compute::DeviceTransfers> transfersBefore = backend.transfers();
      const compute::DeviceMatrix ideal = idealMapsOfNormalized(backend, coarseSpace, coarseCurrent, settings.energy);
      compute::DeviceMatrix columns;
      const GlobalStepInfo step = coarseStep.solveAffine(ideal, columns);
      compute::MapPositions next;
      backend.mapPositions(coarseSpace.faces(), coarseSpace.basePositions(), coarseCorners, columns, {}, coarseCurrent, next);
      info.coarseEpsilons.push_back(step.epsilon);
      info.coarseDisplacements.push_back(next.displacement);  // normalized units: over the diagonal's scale
      info.coarseTransfers.push_back(compute::transfersSince(transfersBefore, backend.transfers()));
      ++info.coarseIterations;
      if (callback) {
        callback({MultiresPhase::Coarse, info.coarseIterations, step.epsilon, next.displacement, next.maxPlanarity,
                  info.coarseTransfers.back()});
      }
      coarseCurrent = std::move(next.positions);
      coarseColumns = std::move(columns);
      converged = next.displacement < settings.tolerance;
    }
    FaceMaps coarseMaps = coarseSpace.identityMaps();
    if (info.coarseIterations > 0) {
      const Eigen::MatrixXd& x = coarseColumns.values();
      for (Index f = 0; f < coarseSpace.faceCount(); ++f) coarseMaps.maps[f].leftCols<3>() = x.middleRows<4>(4 * f);
    }
    if (!converged) info.status = MultiresStatus::MaxIterationsReached;
    info.coarseSeconds = secondsSince(coarseStart);

    // Prolongation (§6.3) and the fine global step with the user's constraints.
    const auto fineStart = SteadyClock::now();
    const ShapeSpace fineSpace(fineMesh);
    const auto prolonged = prolongMaps(coarseMaps.maps, coarseSpace.normalization(), fineSpace.normalization(),
                                       hierarchy.ancestorsOfFinestFaces(level));
    std::vector<Index> constrained;
    Positions targets;
    fineConstraints(constraints, positions[finest], constrained, targets);
    GlobalStepSettings fineSettings = settings.global;
    fineSettings.smoothness = settings.smoothness;
    GlobalStep fineStep(backend, fineSpace, constrained, fineSettings);
    FaceMaps fineMaps;
    info.fineStep = fineStep.solve(prolonged, targets, fineMaps);
    result.positions = fineSpace.positions(fineMaps.maps);
    // Only if eps > 0 left the faces above the bound: §5 projection iterations, on the
    // fine mesh's normalized positions where the backend computes them (on a device the
    // fits, the solution and the positions stay there; the positions come back at the end).
    const double bound = std::max(settings.planarityTolerance, planarityStats(fineMesh).max);
    double planarity = planarityStats(PolygonMesh{result.positions, fineMesh.faces}).max;
    if (settings.maxProjectionIterations > 0 && planarity > bound) {
      const compute::VertexCorners corners = fineSpace.vertexCorners();
      compute::DeviceMatrix current(Eigen::MatrixXd(normalizedTargetPositions(fineSpace, result.positions)));
      for (int it = 0; it < settings.maxProjectionIterations && planarity > bound; ++it) {
        throwIfCancelled("multi-resolution deformation (projection)");
        const std::optional<compute::DeviceTransfers> transfersBefore = backend.transfers();
        compute::DeviceProjectiveFits fits;
        compute::DeviceMatrix columns;
        fineStep.solveProjectiveFitsAt(current, targets, fits, columns);
        compute::MapPositions next;
        backend.mapPositions(fineSpace.faces(), fineSpace.basePositions(), corners, columns, fits.reciprocalScales,
                             current, next);
        current = std::move(next.positions);
        planarity = next.maxPlanarity;
        info.projectionTransfers.push_back(compute::transfersSince(transfersBefore, backend.transfers()));
        ++info.projectionIterations;
        if (callback) {
          callback({MultiresPhase::Projection, info.projectionIterations, 0.0, 0.0, planarity,
                    info.projectionTransfers.back()});
        }
      }
      result.positions = fineSpace.normalization().toWorld(Positions(current.values()));
    }
    info.prolongationSeconds = secondsSince(fineStart);
  }

  info.planarity = planarityStats(PolygonMesh{result.positions, fineMesh.faces}, settings.planarityTolerance);
  if (info.planarity.max > std::max(settings.planarityTolerance, planarityStats(fineMesh).max)) {
    info.status = MultiresStatus::MaxIterationsReached;
  }
  for (const Index v : constraints.fixed) {
    info.maxFixedError = std::max(info.maxFixedError, (result.positions.row(v) - positions[finest].row(v)).norm());
  }
  for (const Handle& h : constraints.handles) {
    info.maxHandleError =
        std::max(info.maxHandleError, (result.positions.row(h.vertex) - h.position.transpose()).norm());
  }
  info.seconds = secondsSince(start);
  return result;
}

}  // namespace plano::projective
