#include "projective/IdealMaps.h"

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "core/Error.h"

namespace plano::projective {
namespace {

/// Per-face data of the linearization: source centroid, its image, the linear map L and
/// the in-plane similarity scale.
struct Linearization {
  Eigen::RowVector3d centroid;
  Eigen::RowVector3d image;
  Eigen::Matrix3d linear;
  double similarityScale = 1.0;
};

Linearization linearize(const ShapeSpace& space, Index f, const Eigen::Matrix4d& T) {
  const auto face = space.faces()[f];
  const auto k = static_cast<Eigen::Index>(face.size());
  Eigen::MatrixXd points(k, 3);
  for (Eigen::Index i = 0; i < k; ++i) points.row(i) = space.basePositions().row(face[i]);
  Linearization lin;
  lin.centroid = points.colwise().mean();
  const Eigen::MatrixXd centred = points.rowwise() - lin.centroid;
  // Source plane basis: eigenvectors of the covariance, normal = smallest eigenvalue.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(centred.transpose() * centred);
  const Eigen::RowVector3d e1 = eig.eigenvectors().col(2).transpose();
  const Eigen::RowVector3d e2 = eig.eigenvectors().col(1).transpose();
  const Eigen::RowVector3d n = e1.cross(e2);

  const Eigen::RowVector4d h = homogeneous(lin.centroid) * T;
  if (!(std::abs(h[3]) > 1e-12) || !h.allFinite()) {
    throwNumerical("closest ideal map: the fitted map of face " + std::to_string(f) +
                   " sends the face centroid to infinity");
  }
  lin.image = h.head<3>() / h[3];
  // Jacobian of x -> ((x,1)T)_xyz / ((x,1)T)_w at the centroid, row-vector convention
  // (dphi = dx J): J(k, j) = (T(k, j) - phi_j T(k, 3)) / w.
  const Eigen::Matrix3d J = (T.topLeftCorner<3, 3>() - T.topRightCorner<3, 1>() * lin.image) / h[3];
  const Eigen::RowVector3d a = e1 * J;
  const Eigen::RowVector3d b = e2 * J;
  const Eigen::RowVector3d axb = a.cross(b);
  const double area = axb.norm();
  Eigen::Matrix3d images;
  if (area > 1e-300) {
    images << a, b, axb / std::sqrt(area);  // normal scaled like the plane: |n'| = sqrt(area scale)
  } else {
    images << a, b, n * J;  // face collapsed to a segment or point: nothing better than J
  }
  Eigen::Matrix3d basis;
  basis << e1, e2, n;
  lin.linear = basis.transpose() * images;  // basis is orthonormal: basis^-1 = basis^T
  lin.similarityScale = 0.5 * std::sqrt(a.squaredNorm() + b.squaredNorm() + 2.0 * area);
  return lin;
}

}  // namespace

std::vector<Eigen::Matrix4d> closestIdealMaps(compute::Backend& backend, const ShapeSpace& space,
                                              const std::vector<Eigen::Matrix4d>& fitted, IdealMapKind kind) {
  const Index faceCount = space.faceCount();
  if (static_cast<Index>(fitted.size()) != faceCount) {
    throwUsage("closest ideal maps: " + std::to_string(fitted.size()) + " maps given for " +
               std::to_string(faceCount) + " faces");
  }
  std::vector<Linearization> lin(faceCount);
  std::vector<Eigen::Matrix3d> linear(faceCount);
  for (Index f = 0; f < faceCount; ++f) {
    lin[f] = linearize(space, f, fitted[f]);
    linear[f] = lin[f].linear;
  }
  std::vector<Eigen::Matrix3d> rotations(faceCount);
  std::vector<Eigen::Vector3d> singularValues(faceCount);
  backend.closestRotations(linear, rotations, singularValues);

  std::vector<Eigen::Matrix4d> ideal(faceCount, Eigen::Matrix4d::Identity());
  for (Index f = 0; f < faceCount; ++f) {
    const double s = kind == IdealMapKind::Similar ? lin[f].similarityScale : 1.0;
    const Eigen::Matrix3d M = s * rotations[f];
    ideal[f].topLeftCorner<3, 3>() = M;
    ideal[f].block<1, 3>(3, 0) = lin[f].image - lin[f].centroid * M;
  }
  return ideal;
}

}  // namespace plano::projective
