#include "subspace/FaceConstraintBlocks.h"

#include <Eigen/Dense>
#include <string>

#include "core/Error.h"

namespace plano::subspace {
namespace {

/// Orthonormal basis (k x (k - r)) of the complement of the column space of A (k x r, full rank).
Eigen::MatrixXd complementBasis(const Eigen::MatrixXd& A) {
  const Eigen::Index k = A.rows(), r = A.cols();
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(k, k);
  return Q.rightCols(k - r);
}

/// Rows m_j^T (x) a^T for the columns m_j of M: they act on a face's 3k coordinates.
void appendKroneckerRows(const Eigen::MatrixXd& M, const Eigen::Vector3d& a, Eigen::MatrixXd& out, Eigen::Index row0) {
  for (Eigen::Index j = 0; j < M.cols(); ++j)
    for (Eigen::Index i = 0; i < M.rows(); ++i)
      for (int c = 0; c < 3; ++c) out(row0 + j, 3 * i + c) = M(i, j) * a[c];
}

}  // namespace

FaceFrame fitFaceFrame(const Positions& Y, std::span<const Index> face, Index f, double degeneracy) {
  const Eigen::Index k = static_cast<Eigen::Index>(face.size());
  Eigen::MatrixX3d P(k, 3);
  for (Eigen::Index i = 0; i < k; ++i) P.row(i) = Y.row(face[i]);
  FaceFrame frame;
  frame.centroid = P.colwise().mean().transpose();
  P.rowwise() -= frame.centroid.transpose();
  if (!P.allFinite()) throwBadInput("face " + std::to_string(f) + " has a non-finite corner");
  Eigen::JacobiSVD<Eigen::MatrixX3d> svd(P, Eigen::ComputeFullV);  // thin V needs a dynamic column count
  const Eigen::Vector3d s = svd.singularValues();
  frame.flatness = s[0] > 0.0 ? s[1] / s[0] : 0.0;
  frame.nonPlanarity = s[0] > 0.0 ? s[2] / s[0] : 0.0;
  if (!(frame.flatness > degeneracy)) {
    throwBadInput("face " + std::to_string(f) + " is degenerate (its corners are collinear or coincide)");
  }
  frame.axis1 = svd.matrixV().col(0);
  frame.axis2 = svd.matrixV().col(1);
  frame.normal = frame.axis1.cross(frame.axis2).normalized();
  frame.planar.resize(k, 2);
  frame.planar.col(0) = P * frame.axis1;
  frame.planar.col(1) = P * frame.axis2;
  return frame;
}

Eigen::MatrixXd affineFaceBlock(const FaceFrame& frame) {
  const Eigen::Index k = frame.planar.rows();
  Eigen::MatrixXd A(k, 3);
  A.col(0).setOnes();
  A.rightCols(2) = frame.planar;
  return complementBasis(A).transpose();
}

Eigen::MatrixXd parallelFaceBlock(const FaceFrame& frame) {
  const Eigen::Index k = frame.planar.rows();
  const Eigen::MatrixXd Q = complementBasis(Eigen::MatrixXd::Ones(k, 1));
  Eigen::MatrixXd block = Eigen::MatrixXd::Zero(k - 1, 3 * k);
  appendKroneckerRows(Q, frame.normal, block, 0);
  return block;
}

Eigen::MatrixXd faceBlock(const FaceFrame& frame, FaceSpace space, const Eigen::Vector3d& up) {
  switch (space) {
    case FaceSpace::Parallel: return parallelFaceBlock(frame);
    case FaceSpace::Vertical: return verticalFaceBlock(frame, up);
    case FaceSpace::Affine: break;
  }
  const Eigen::MatrixXd scalar = affineFaceBlock(frame);
  const Eigen::Index k = frame.planar.rows();
  Eigen::MatrixXd block = Eigen::MatrixXd::Zero(3 * scalar.rows(), 3 * k);
  for (Eigen::Index r = 0; r < scalar.rows(); ++r)
    for (Eigen::Index i = 0; i < k; ++i)
      for (int c = 0; c < 3; ++c) block(3 * r + c, 3 * i + c) = scalar(r, i);
  return block;
}

bool isHorizontal(const FaceFrame& frame, const Eigen::Vector3d& up, double tolerance) {
  return up.normalized().cross(frame.normal).norm() <= tolerance;
}

Eigen::MatrixXd verticalFaceBlock(const FaceFrame& frame, const Eigen::Vector3d& up) {
  const Eigen::Index k = frame.planar.rows();
  const Eigen::Vector3d N = up.normalized().cross(frame.normal).normalized();
  const Eigen::Vector3d E = N.cross(frame.normal);  // In-plane, perpendicular to N.
  // Corner coordinates along E (centred), from the in-plane coordinates.
  const Eigen::Vector2d e(E.dot(frame.axis1), E.dot(frame.axis2));
  Eigen::MatrixXd A(k, 2);
  A.col(0).setOnes();
  A.col(1) = frame.planar * e;
  const Eigen::MatrixXd M = complementBasis(A);
  // (X_f x N) M = 0  <=>  a^T X_f M = 0 and b^T X_f M = 0 for an orthonormal basis {a, b} of N^perp.
  Eigen::MatrixXd block = Eigen::MatrixXd::Zero(2 * (k - 2), 3 * k);
  appendKroneckerRows(M, frame.normal, block, 0);
  appendKroneckerRows(M, E, block, k - 2);
  return block;
}

}  // namespace plano::subspace
