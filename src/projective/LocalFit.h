#pragma once
// Local step of the projective-maps paper (§4.1, Eq. 3): the projective map of one face.
#include <Eigen/Core>
#include <span>
#include <vector>

namespace plano::projective {

/// A fitted face map. Row-vector convention: (p_i, 1) T = shat_i (q_i, 1), where shat_i =
/// 1 / s_{f,i} is the reciprocal of the paper's scale factor, normalized so that the mean of
/// shat_i over the face's corners is 1 (see fitProjectiveMap).
struct ProjectiveFit {
  Eigen::Matrix4d map = Eigen::Matrix4d::Identity();
  std::vector<double> reciprocalScales;  ///< One per corner.
  /// RMS residual of the 3k fit equations (0 for an exact fit).
  double residual = 0.0;
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
///
/// The fit is solved in coordinates centred at each face's own corner centroids (source
/// and target), where T'(3, 3) = 1 means "mean reciprocal scale 1": uncentred, more than
/// four corners that are not an exact projective image admit the degenerate exact solution
/// T = n_h r^T (n_h the homogeneous source plane), which collapses the face (all shat_i = 0).
/// T' is then converted back, keeping its scale: shat_i = (p_i, 1) T[:, 3] has mean 1 over
/// the face. This departs from the paper's T(3, 3) = 1 (§3), which normalizes every face at
/// the global origin: a projective map is the same map at any scale, but the global step's
/// objective ||A_f - T_f||^2 weighs each face by its map's scale squared, and T(3, 3) = 1
/// blows that scale up (without bound, or flips its sign) on a face whose map sends the
/// origin near its plane at infinity. With mean reciprocal scale 1 every face weighs alike,
/// as every ideal (affine) map does; an affine fit has T(3, 3) = 1 either way.
/// Coordinates should be centred and scaled to unit size (see projective-notes).
ProjectiveFit fitProjectiveMap(std::span<const Eigen::Vector3d> source, std::span<const Eigen::Vector3d> target,
                               const LocalFitSettings& settings = {});

/// Orthogonal projection of points onto their least-squares plane.
std::vector<Eigen::Vector3d> projectOntoBestFitPlane(std::span<const Eigen::Vector3d> points);

}  // namespace plano::projective
