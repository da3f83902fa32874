#pragma once
// Interpolation and extrapolation between two polyhedral meshes of the same topology
// (projective-maps paper, §7.1).
//
// The local step gives the map T_f of every face from mesh A to mesh B (exact for planar
// faces). Each is factored into a pure projective and an affine part (Eq. 5, row-vector
// convention, T(3, 3) = 1):
//
//   T = T_proj T_aff = [[I, J], [0, 1]] [[H, 0], [Y, 1]] = [[H + J Y, J], [Y, 1]],
//
// so J = T[0:3, 3], Y = T[3, 0:3] and H = T[0:3, 0:3] - J Y. H = Q R (left polar
// decomposition: Q symmetric positive definite, R a rotation), and for any t
//
//   H(t) = (t Q + (1 - t) I) R^t,  Y(t) = t Y,  J(t) = t J,  T(t) = T_proj(t) T_aff(t).
//
// The paper writes Y(t) = (1 - t) Y and J(t) = (1 - t) J next to H(t) = (tQ + (1-t)I) R^t;
// with H(0) = I the consistent choice is the one above, which gives T(0) = I (mesh A) and
// T(1) = T (mesh B). The prescribed T_f(t) are then projected with the global step.
#include <Eigen/Core>
#include <vector>

#include "compute/Backend.h"
#include "projective/GlobalStep.h"
#include "projective/ShapeSpace.h"

namespace plano::projective {

/// The factors of one face map.
struct MapFactors {
  Eigen::Matrix3d stretch = Eigen::Matrix3d::Identity();   ///< Q, symmetric positive definite.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< R.
  Eigen::RowVector3d translation = Eigen::RowVector3d::Zero();  ///< Y.
  Eigen::Vector3d perspective = Eigen::Vector3d::Zero();        ///< J.
};

/// Factor T (T(3, 3) = 1) as above. Throws Error(Numerical) when H is singular or
/// reverses orientation (R would be a reflection, which has no real power R^t).
MapFactors factorMap(const Eigen::Matrix4d& T);

/// T(t) from the factors: T(0) = I, T(1) = the factored map.
Eigen::Matrix4d interpolatedMap(const MapFactors& factors, double t);

struct InterpolationSettings {
  /// With unconstrained affine-ish targets the collapsed mesh is a feasible exact
  /// solution, so eps = 0 always exists; try it first (exactly planar faces).
  GlobalStepSettings global = [] {
    GlobalStepSettings s;
    s.epsilonStart = EpsilonStart::ExactFirst;
    return s;
  }();
};

class Interpolation {
 public:
  /// Precompute: shape space of A, fits A -> B, their factors.
  ///   a, b  in: meshes with the same faces (vertex order and count); throws
  ///         Error(BadInput) naming the first differing face otherwise.
  Interpolation(compute::Backend& backend, const PolygonMesh& a, const PolygonMesh& b,
                const InterpolationSettings& settings = {});

  /// The mesh at t (t = 0: A, t = 1: B, any real t extrapolates), and the global step's info.
  PolygonMesh at(double t, GlobalStepInfo* info = nullptr);

  const ShapeSpace& space() const { return space_; }

 private:
  compute::Backend& backend_;
  ShapeSpace space_;
  std::vector<MapFactors> factors_;
  GlobalStep global_;
};

}  // namespace plano::projective
