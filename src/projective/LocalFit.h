#pragma once
// Local step of the projective-maps paper (§4.1, Eq. 3): the projective map of one face.
#include <Eigen/Core>
#include <span>
#include <vector>

namespace plano::projective {

/// A fitted face map. Row-vector convention: (p_i, 1) T = shat_i (q_i, 1), T(3, 3) = 1,
/// where shat_i = 1 / s_{f,i} is the reciprocal of the paper's scale factor.
struct ProjectiveFit {
  Eigen::Matrix4d map = Eigen::Matrix4d::Identity();
  std::vector<double> reciprocalScales;  ///< One per corner.
  double residual = 0.0;  ///< RMS residual of the 3k fit equations (0 for an exact fit).
  int rank = 0;           ///< Numerical rank of the 3k x 15 system.
};

struct LocalFitSettings {
  /// Project both corner sets onto their best-fitting planes first (§5 step 1), which
  /// keeps near-planar input from exploiting the ambient projective freedom.
  bool projectOntoPlanes = true;
  /// Relative rank threshold of the complete orthogonal factorization.
  double rankThreshold = 1e-10;
};

/// Best projective map from the source corners p_i to the target corners q_i of one face
/// (k >= 3 corners). Unknowns are the 15 free entries of T; the reciprocal scales are
/// eliminated (shat_i = (p_i, 1) T[:, 3]), leaving 3k linear equations
/// (p_i, 1) T[:, j] - q_ij (p_i, 1) T[:, 3] = 0, j = 0..2. When they do not determine T,
/// the solution closest to the identity (Frobenius) is returned, by a complete orthogonal
/// factorization; when they are inconsistent, the least-squares solution.
/// Coordinates should be centred and scaled to unit size (see projective-notes).
ProjectiveFit fitProjectiveMap(std::span<const Eigen::Vector3d> source, std::span<const Eigen::Vector3d> target,
                               const LocalFitSettings& settings = {});

/// Orthogonal projection of points onto their least-squares plane.
std::vector<Eigen::Vector3d> projectOntoBestFitPlane(std::span<const Eigen::Vector3d> points);

}  // namespace plano::projective
