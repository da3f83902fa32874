#pragma once
// Handle-based ASAP / ARAP deformation inside a linear space of polyhedral meshes
// (linear-spaces paper, §3 "Handle-based deformation", Fig. 8; local/global scheme of Liu
// et al. and Sorkine-Alexa). Energy, per face f with centring C:
//   E(X) = sum_f || C X_f - s_f C Y_f R_f^T ||^2  (rows are corners),
// R_f a rotation and s_f a scale (ASAP) or 1 (ARAP). Local step: per-face closest
// rotation of (C X_f)^T (C Y_f) (Procrustes SVD, Backend::closestRotations). Global step: least
// squares over X = N W restricted to the members that meet the positional constraints as
// far as the space allows (W = particular + free V, see ConstrainedSubspace.h); the
// reduced matrix free^T N^T (K (x) I3) N free is factored once. Every iterate is N W,
// hence exactly in the space: exactly polyhedral, not just at convergence.
#include <Eigen/Dense>
#include <functional>
#include <memory>
#include <string>

#include "compute/Backend.h"
#include "compute/ReducedArap.h"
#include "mesh/Constraints.h"
#include "subspace/ConstrainedSubspace.h"
#include "subspace/LinearSpace.h"

namespace plano::subspace {

enum class DeformationEnergy { Asap, Arap };

/// "asap" | "arap"; throws Error(Usage).
DeformationEnergy parseDeformationEnergy(const std::string& text);

struct SubspaceDeformationSettings {
  DeformationEnergy energy = DeformationEnergy::Asap;
  Index maxIterations = 100;
  double tolerance = 1e-8;       ///< Stop when the energy decreases by less than tolerance * energy.
  double rankTolerance = 1e-9;   ///< Rank decisions on the constraint rows C N.
};

enum class DeformationStatus { Converged, IterationLimit };

struct SubspaceDeformationInfo {
  DeformationStatus status = DeformationStatus::IterationLimit;
  Index iterations = 0;
  double energy = 0.0;                 ///< After the last local step.
  double constraintResidual = 0.0;     ///< ||C X - c||: the least the space allows.
  double maxHandleDistance = 0.0;      ///< Largest distance of a constrained vertex from its target.
  double maxSubspaceResidual = 0.0;    ///< max over iterates of ||B vec(X)|| / ||X||.
};

class SubspaceDeformer {
 public:
  /// Precompute: constrain the space, assemble and factor the global matrix. `space` and
  /// `backend` must outlive the deformer. Throws Error(BadInput) for a constraint out of
  /// range, Error(Numerical) when the factorization fails.
  SubspaceDeformer(const LinearSpace& space, const PositionalConstraints& constraints, compute::Backend& backend,
                   const SubspaceDeformationSettings& settings = {});
  ~SubspaceDeformer();
  // The kernels made by solve() refer to this object.
  SubspaceDeformer(const SubspaceDeformer&) = delete;
  SubspaceDeformer& operator=(const SubspaceDeformer&) = delete;

  /// Iterate from X (#V x 3, warm start; the source mesh is a good first guess) and leave
  /// the result in X. `onIterate(k, X)` is called after every global step. The iterations
  /// run on the backend's kernels (Backend::createReducedArapKernels) when it has them.
  /// Throws Error(Numerical) when an iterate is not finite.
  SubspaceDeformationInfo solve(Positions& X, const std::function<void(Index, const Positions&)>& onIterate = {});

  Index freeDimension() const { return static_cast<Index>(constrained_.free.cols()); }
  const ConstrainedSubspace& constrained() const { return constrained_; }

 private:
  class HostKernels;
  /// The global step as a backend's affine map (compute/ReducedArap.h).
  compute::ReducedArapProblem reducedProblem() const;

  const LinearSpace& space_;
  PositionalConstraints constraints_;
  compute::Backend& backend_;
  SubspaceDeformationSettings settings_;
  ConstrainedSubspace constrained_;
  Eigen::MatrixXd reduced_;  ///< N^T (K (x) I3) N.
  Eigen::LDLT<Eigen::MatrixXd> factor_;  ///< Of H = free^T reduced_ free (+ a tiny Tikhonov term).
  Eigen::VectorXd fixedPart_;            ///< reduced_ * particular.
  std::unique_ptr<compute::ReducedArapKernels> kernels_;  ///< The backend's, or HostKernels; made by the first solve.
};

}  // namespace plano::subspace
