#include "projective/Deformation.h"

#include <algorithm>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "mesh/Planarity.h"
#include "projective/ConstrainedVertices.h"
#include "projective/IdealMaps.h"
#include "projective/LocalStep.h"

namespace plano::projective {

const char* toString(DeformationStatus status) {
  switch (status) {
    case DeformationStatus::Converged: return "converged";
    case DeformationStatus::MaxIterationsReached: return "max_iterations";
    case DeformationStatus::NumericalFailure: return "numerical_failure";
  }
  return "unknown";
}

Deformation::Deformation(compute::Backend& backend, const PolygonMesh& base, const PositionalConstraints& constraints,
                         const DeformationSettings& settings)
    : backend_(backend),
      settings_(settings),
      space_(base),
      constrained_(constrainedVertices(constraints)),
      fixedCount_(static_cast<Index>(constraints.fixed.size())),
      global_(backend, space_, constrained_, settings.global) {
  if (settings_.maxIterations < 1) throwUsage("deformation: max iterations must be at least 1");
  if (!(settings_.tolerance > 0.0)) throwUsage("deformation: tolerance must be positive");
}

DeformationInfo Deformation::solve(const Positions& handles, Positions& positions, const DeformationCallback& callback) {
  const auto handleCount = static_cast<Eigen::Index>(constrained_.size()) - fixedCount_;
  if (handles.rows() != handleCount) {
    throwUsage("deformation: " + std::to_string(handles.rows()) + " handle positions for " +
               std::to_string(handleCount) + " handles");
  }
  if (positions.rows() != space_.vertexCount()) positions = space_.baseMesh().vertices;
  Positions targets(constrained_.size(), 3);
  for (Index i = 0; i < fixedCount_; ++i) targets.row(i) = space_.baseMesh().vertices.row(constrained_[i]);
  if (handleCount > 0) targets.bottomRows(handleCount) = handles;

  const double planarityBound = std::max(settings_.planarityTolerance, planarityStats(space_.baseMesh()).max);
  DeformationInfo info;
  std::optional<compute::DeviceTransfers> transfersBefore;
  // displacement: normalized units (world distance over the diagonal's scale).
  auto record = [&](DeformationPhase phase, const GlobalStepInfo& step, double displacement, double planarity) {
    DeformationIteration it;
    it.transfers = compute::transfersSince(transfersBefore, backend_.transfers());
    it.iteration = ++info.iterations;
    it.phase = phase;
    it.epsilon = step.epsilon;
    it.initialViolation = step.initialViolation;
    it.constraintResidual = step.constraintResidual;
    it.positionalResidual = step.positionalResidual;
    it.admmIterations = step.admmIterations;
    it.linearIterations = step.linearIterations;
    it.polishRefinements = step.polishRefinements;
    it.attempts = step.attempts;
    it.displacement = displacement;
    it.maxPlanarity = planarity;
    info.history.push_back(it);
    if (callback) callback(it);
    return it;
  };

  // The positions, normalized, where the backend computes them: on a device both loops
  // below move no mesh-sized data between host and device (the fits, the global step's
  // solution and these positions stay there; scalars come back).
  compute::DeviceMatrix current(Eigen::MatrixXd(normalizedTargetPositions(space_, positions)));
  bool currentIsNewer = false;  // `current` holds positions that `positions` does not yet
  const compute::VertexCorners corners = space_.vertexCorners();
  auto advance = [&](DeformationPhase phase, const GlobalStepInfo& step, const compute::DeviceMatrix& columns,
                     const compute::DeviceMatrix& cornerWeights) {
    compute::MapPositions next;
    backend_.mapPositions(space_.faces(), space_.basePositions(), corners, columns, cornerWeights, current, next);
    const DeformationIteration it = record(phase, step, next.displacement, next.maxPlanarity);
    current = std::move(next.positions);
    currentIsNewer = true;
    return it;
  };
  try {
    bool converged = false;
    // Phase 1 (§6.1): fit, closest rigid/similar map, global step.
    for (int k = 0; k < settings_.maxIterations && !converged; ++k) {
      throwIfCancelled("deformation");
      transfersBefore = backend_.transfers();
      const compute::DeviceMatrix ideal = idealMapsOfNormalized(backend_, space_, current, settings_.energy);
      compute::DeviceMatrix columns;
      const GlobalStepInfo step = global_.solveAffine(ideal, targets, columns);
      converged = advance(DeformationPhase::Ideal, step, columns, {}).displacement < settings_.tolerance;
    }
    // Phase 2 (§5 loop): projective fits of the current faces, projected with the same
    // constraints, until the faces are planar again.
    bool planar = !info.history.empty() && info.history.back().maxPlanarity <= planarityBound;
    for (int k = 0; k < settings_.maxProjectionIterations && !planar; ++k) {
      throwIfCancelled("deformation (projection)");
      transfersBefore = backend_.transfers();
      compute::DeviceProjectiveFits fits;
      compute::DeviceMatrix columns;
      const GlobalStepInfo step = global_.solveProjectiveFitsAt(current, targets, fits, columns);
      planar = advance(DeformationPhase::Projection, step, columns, fits.reciprocalScales).maxPlanarity <=
               planarityBound;
    }
    if (currentIsNewer) positions = space_.normalization().toWorld(Positions(current.values()));
    info.status = converged && planar ? DeformationStatus::Converged : DeformationStatus::MaxIterationsReached;
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::Numerical) throw;
    info.status = DeformationStatus::NumericalFailure;
    info.message = e.what();
    // The last positions the loop computed (their array is never the one a failed step wrote).
    if (currentIsNewer) positions = space_.normalization().toWorld(Positions(current.values()));
  }

  info.planarity = planarityStats(PolygonMesh{positions, space_.faces()});
  for (std::size_t i = 0; i < constrained_.size(); ++i) {
    info.maxConstraintError = std::max(info.maxConstraintError, (positions.row(constrained_[i]) - targets.row(i)).norm());
  }
  return info;
}

DeformationResult deform(compute::Backend& backend, const PolygonMesh& base, const PositionalConstraints& constraints,
                         const DeformationSettings& settings, const DeformationCallback& callback) {
  Deformation deformation(backend, base, constraints, settings);
  Positions handles(constraints.handles.size(), 3);
  for (std::size_t i = 0; i < constraints.handles.size(); ++i) handles.row(i) = constraints.handles[i].position.transpose();
  DeformationResult result;
  result.mesh.faces = base.faces;
  result.mesh.vertices = base.vertices;
  result.info = deformation.solve(handles, result.mesh.vertices, callback);
  return result;
}

}  // namespace plano::projective
