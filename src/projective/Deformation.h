#pragma once
// Single-level deformation in the projective shape space (projective-maps paper, §6.1):
// fixed vertices and moved handles are positional constraints; the local step fits a
// projective map per face and replaces it by the closest rigid or similarity map
// (App. A), the global step projects those onto the compatible maps (Eq. 4); the two
// alternate until the largest vertex displacement between iterations falls below a
// tolerance. Every output face is the image of a base face under one map, so faces stay
// planar up to the eps of the global step. When the rigid/similar phase ends above the
// planarity tolerance (eps > 0 was needed), a few iterations of the paper's §5 loop
// (projective fit to the current faces, global step with the same constraints) bring the
// faces back to planarity without moving the constraints.
#include <functional>
#include <string>
#include <vector>

#include "compute/Backend.h"
#include "mesh/Constraints.h"
#include "mesh/Planarity.h"
#include "projective/GlobalStep.h"
#include "projective/IdealMaps.h"

namespace plano::projective {

struct DeformationSettings {
  IdealMapKind energy = IdealMapKind::Rigid;
  int maxIterations = 100;
  /// Stop when max_v |q_v^k - q_v^(k-1)| < tolerance * bounding-box diagonal.
  double tolerance = 1e-4;
  /// Percent (paper's measure). After the rigid/similar phase, the §5 projection phase
  /// runs while the max face planarity exceeds this or the base mesh's own max planarity,
  /// whichever is larger (a deformation is not asked to be flatter than its input).
  double planarityTolerance = 0.1;
  int maxProjectionIterations = 20;
  /// Global step settings. Deformation tries eps = 0 first: the affine shape space of a
  /// polyhedral mesh often contains exact solutions, which keep every face exactly planar.
  GlobalStepSettings global = [] {
    GlobalStepSettings s;
    s.epsilonStart = EpsilonStart::ExactFirst;
    return s;
  }();
};

enum class DeformationStatus {
  Converged,             ///< Displacement and planarity below their tolerances.
  MaxIterationsReached,  ///< Stopped by an iteration cap.
  NumericalFailure,      ///< A step threw Error(Numerical); positions are the last good ones.
};

const char* toString(DeformationStatus status);

enum class DeformationPhase { Ideal, Projection };

/// One local/global iteration.
struct DeformationIteration {
  int iteration = 0;  ///< 1-based, over both phases.
  DeformationPhase phase = DeformationPhase::Ideal;
  double epsilon = 0.0;
  double initialViolation = 0.0;    ///< max |C_s T - d| of the step's targets (normalized units).
  double constraintResidual = 0.0;  ///< max |C_s A - d| after the step.
  double positionalResidual = 0.0;
  int admmIterations = 0;
  /// Of the ADMM's solves with K: one per ADMM iteration on the CPU, PCG iterations on the
  /// device (GlobalStepInfo::linearIterations).
  long linearIterations = 0;
  /// Method-of-multipliers refinements of the step's polish or direct equality solve
  /// (GlobalStepInfo::polishRefinements).
  int polishRefinements = 0;
  double displacement = 0.0;        ///< Max vertex move this iteration / bounding-box diagonal.
  double maxPlanarity = 0.0;        ///< Percent, after the iteration.
  std::vector<EpsilonAttempt> attempts;  ///< The eps schedule of the global step.
  /// Host <-> device copies of the iteration (compute::Backend::transfers; none on the CPU).
  std::optional<compute::DeviceTransfers> transfers;
};

struct DeformationInfo {
  DeformationStatus status = DeformationStatus::MaxIterationsReached;
  int iterations = 0;
  std::vector<DeformationIteration> history;
  PlanarityStats planarity;        ///< Of the result.
  double maxConstraintError = 0.0;  ///< World units: max distance of a constrained vertex to its position.
  std::string message;             ///< Why a NumericalFailure happened.
};

/// Called after every iteration (for progress output); may be empty.
using DeformationCallback = std::function<void(const DeformationIteration&)>;

class Deformation {
 public:
  /// Precompute: shape space of the base mesh and the global step's row layout.
  ///   base         in: the polyhedral base mesh (world coordinates).
  ///   constraints  in: fixed vertices (kept at their base positions) and handle vertices.
  /// Throws Error(BadInput) for out-of-range or repeated constraint vertices.
  Deformation(compute::Backend& backend, const PolygonMesh& base, const PositionalConstraints& constraints,
              const DeformationSettings& settings = {});

  /// Deform with the handle positions of `handles` (#handles x 3, the constructor's order).
  ///   positions  in/out: #V x 3 initial guess (e.g. the base or the last result), result.
  /// Numerical failures are reported in the returned status, never thrown.
  DeformationInfo solve(const Positions& handles, Positions& positions, const DeformationCallback& callback = {});

  const ShapeSpace& space() const { return space_; }

 private:
  compute::Backend& backend_;
  DeformationSettings settings_;
  ShapeSpace space_;
  std::vector<Index> constrained_;  ///< Fixed vertices, then handles.
  Index fixedCount_ = 0;
  GlobalStep global_;
};

struct DeformationResult {
  PolygonMesh mesh;
  DeformationInfo info;
};

/// One-call deformation of `base` with the handles of `constraints` moved to their positions.
DeformationResult deform(compute::Backend& backend, const PolygonMesh& base, const PositionalConstraints& constraints,
                         const DeformationSettings& settings = {}, const DeformationCallback& callback = {});

}  // namespace plano::projective
