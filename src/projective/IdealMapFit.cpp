#include "projective/IdealMapFit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace plano::projective {
namespace {

using Corners = Eigen::Matrix<double, Eigen::Dynamic, 3>;

Eigen::RowVector4d homogeneousRow(const Eigen::RowVector3d& p) { return {p.x(), p.y(), p.z(), 1.0}; }

/// The fit sends the centroid or a corner through the plane at infinity (weights of mixed
/// sign or ~0): its Jacobian at the centroid says nothing about the face.
bool sendsFaceToInfinity(const Corners& source, const Eigen::Matrix4d& T, const Eigen::RowVector3d& centroid) {
  const double w = homogeneousRow(centroid).dot(T.col(3));
  if (!(std::abs(w) > 1e-12) || !std::isfinite(w)) return true;
  for (Eigen::Index i = 0; i < source.rows(); ++i) {
    if (!(homogeneousRow(source.row(i)).dot(T.col(3)) * w > 0.0)) return true;
  }
  return false;
}

/// Kabsch/Umeyama between the source and target corners.
IdealMapLinearization cornerProcrustes(const Corners& source, const Corners& target) {
  IdealMapLinearization lin;
  lin.method = compute::IdealMapMethod::CornerProcrustes;
  lin.centroid = source.colwise().mean();
  lin.image = target.colwise().mean();
  lin.linear.setZero();
  lin.sourceSpread = 0.0;
  for (Eigen::Index i = 0; i < source.rows(); ++i) {
    const Eigen::RowVector3d p = source.row(i) - lin.centroid;
    lin.linear += p.transpose() * (target.row(i) - lin.image);
    lin.sourceSpread += p.squaredNorm();
  }
  return lin;
}

}  // namespace

IdealMapLinearization linearizeFaceMap(const Corners& source, const Eigen::Matrix4d& T, const Corners* target) {
  IdealMapLinearization lin;
  lin.centroid = source.colwise().mean();
  if (target && sendsFaceToInfinity(source, T, lin.centroid)) return cornerProcrustes(source, *target);

  const Eigen::RowVector4d h = homogeneousRow(lin.centroid) * T;
  if (!(std::abs(h[3]) > 1e-12) || !h.allFinite()) {
    lin.method = compute::IdealMapMethod::CentroidAtInfinity;
    return lin;
  }
  const Corners centred = source.rowwise() - lin.centroid;
  // Source plane basis: eigenvectors of the covariance, normal = smallest eigenvalue.
  // (The linear map below does not depend on which orthonormal basis of the plane this is.)
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(centred.transpose() * centred);
  const Eigen::RowVector3d e1 = eig.eigenvectors().col(2).transpose();
  const Eigen::RowVector3d e2 = eig.eigenvectors().col(1).transpose();
  const Eigen::RowVector3d n = e1.cross(e2);

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

Eigen::Matrix4d idealMapOf(const IdealMapLinearization& lin, const Eigen::Matrix3d& R,
                           const Eigen::Vector3d& singularValues, bool similar) {
  double s = 1.0;
  if (similar) {
    s = lin.method == compute::IdealMapMethod::CornerProcrustes
            ? std::max(singularValues.sum(), 0.0) / std::max(lin.sourceSpread, 1e-300)
            : lin.similarityScale;
  }
  const Eigen::Matrix3d M = s * R;
  Eigen::Matrix4d ideal = Eigen::Matrix4d::Identity();
  ideal.topLeftCorner<3, 3>() = M;
  ideal.block<1, 3>(3, 0) = lin.image - lin.centroid * M;
  return ideal;
}

}  // namespace plano::projective
