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
  /// Corner-set Procrustes instead of the Jacobian: the scale is Umeyama's,
  /// sum of signed singular values of `linear` / sourceSpread.
  bool procrustes = false;
  double sourceSpread = 1.0;
};

/// The fit sends the centroid or a corner through the plane at infinity (weights of
/// mixed sign or ~0): its Jacobian at the centroid says nothing about the face.
bool degenerate(const ShapeSpace& space, Index f, const Eigen::Matrix4d& T, const Eigen::RowVector3d& centroid) {
  const double w = homogeneous(centroid).dot(T.col(3));
  if (!(std::abs(w) > 1e-12) || !std::isfinite(w)) return true;
  for (Index v : space.faces()[f]) {
    if (!(homogeneous(space.basePositions().row(v)).dot(T.col(3)) * w > 0.0)) return true;
  }
  return false;
}

/// Kabsch/Umeyama between the source and target corners of face f.
Linearization cornerProcrustes(const ShapeSpace& space, Index f, const Positions& target) {
  const auto face = space.faces()[f];
  Linearization lin;
  lin.procrustes = true;
  lin.centroid.setZero();
  lin.image.setZero();
  for (Index v : face) {
    lin.centroid += space.basePositions().row(v);
    lin.image += target.row(v);
  }
  lin.centroid /= static_cast<double>(face.size());
  lin.image /= static_cast<double>(face.size());
  lin.linear.setZero();
  lin.sourceSpread = 0.0;
  for (Index v : face) {
    const Eigen::RowVector3d p = space.basePositions().row(v) - lin.centroid;
    lin.linear += p.transpose() * (target.row(v) - lin.image);
    lin.sourceSpread += p.squaredNorm();
  }
  return lin;
}

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
                                              const std::vector<Eigen::Matrix4d>& fitted, IdealMapKind kind,
                                              const Positions* target, Index* fallbacks) {
  const Index faceCount = space.faceCount();
  if (static_cast<Index>(fitted.size()) != faceCount) {
    throwUsage("closest ideal maps: " + std::to_string(fitted.size()) + " maps given for " +
               std::to_string(faceCount) + " faces");
  }
  std::vector<Linearization> lin(faceCount);
  std::vector<Eigen::Matrix3d> linear(faceCount);
  if (target && target->rows() != space.vertexCount()) {
    throwUsage("closest ideal maps: target has " + std::to_string(target->rows()) + " vertices, the mesh " +
               std::to_string(space.vertexCount()));
  }
  if (fallbacks) *fallbacks = 0;
  for (Index f = 0; f < faceCount; ++f) {
    Eigen::RowVector3d centroid = Eigen::RowVector3d::Zero();
    for (Index v : space.faces()[f]) centroid += space.basePositions().row(v);
    centroid /= static_cast<double>(space.faces().degree(f));
    if (target && degenerate(space, f, fitted[f], centroid)) {
      lin[f] = cornerProcrustes(space, f, *target);
      if (fallbacks) ++*fallbacks;
    } else {
      lin[f] = linearize(space, f, fitted[f]);
    }
    linear[f] = lin[f].linear;
  }
  std::vector<Eigen::Matrix3d> rotations(faceCount);
  std::vector<Eigen::Vector3d> singularValues(faceCount);
  backend.closestRotations(linear, rotations, singularValues);

  std::vector<Eigen::Matrix4d> ideal(faceCount, Eigen::Matrix4d::Identity());
  for (Index f = 0; f < faceCount; ++f) {
    double s = 1.0;
    if (kind == IdealMapKind::Similar) {
      s = lin[f].procrustes ? std::max(singularValues[f].sum(), 0.0) / std::max(lin[f].sourceSpread, 1e-300)
                            : lin[f].similarityScale;
    }
    const Eigen::Matrix3d M = s * rotations[f];
    ideal[f].topLeftCorner<3, 3>() = M;
    ideal[f].block<1, 3>(3, 0) = lin[f].image - lin[f].centroid * M;
  }
  return ideal;
}

}  // namespace plano::projective
