#pragma once
// Uniform scalings along a line (projective-maps paper, §7): the prescribed maps
// T_f(t) = diag(t, t, t, 1) (about a pivot) are affine, so they induce unit scale factors
// and the global step projects onto one fixed linear subspace. With eps = 0 that
// projection is an affine function of the targets, and T_f(t) is affine in t: two solves,
// at t1 and t2, give every other t by linear interpolation of the maps, exactly
// compatible (hence exactly planar faces) for any t, including extrapolation and t = 0
// ("as-minimal-as-possible").
#include <vector>

#include "projective/MapPrescription.h"

namespace plano::projective {

class UniformScalingFamily {
 public:
  /// Precompute: two global steps with the prescribed scalings t1 and t2 (t1 != t2) on
  /// `faces` (empty = all) and the positional constraints. Both solves are exact
  /// (eps = 0, always feasible: the identity satisfies every row when the handles are at
  /// rest, and the scaled solutions otherwise); throws Error(Numerical) if the QP fails.
  UniformScalingFamily(compute::Backend& backend, const PolygonMesh& base, Pivot pivot, const std::vector<Index>& faces,
                       const PositionalConstraints& constraints, double t1 = 0.0, double t2 = 1.0,
                       const GlobalStepSettings& settings = {});

  /// Maps A(t) = A(t1) + (t - t1) / (t2 - t1) (A(t2) - A(t1)); no solve.
  std::vector<Eigen::Matrix4d> maps(double t) const;
  /// The mesh at scaling t (world coordinates).
  PolygonMesh mesh(double t) const;

  const GlobalStepInfo& firstSolve() const { return info1_; }
  const GlobalStepInfo& secondSolve() const { return info2_; }
  const ShapeSpace& space() const { return space_; }

 private:
  ShapeSpace space_;
  double t1_;
  double t2_;
  FaceMaps first_;
  FaceMaps second_;
  GlobalStepInfo info1_;
  GlobalStepInfo info2_;
};

}  // namespace plano::projective
