#include "projective/LocalFit.h"

#include <Eigen/Dense>
#include <cmath>

namespace plano::projective {

namespace {

constexpr std::size_t kStackCorners = 8;
using StackFitMatrix = Eigen::Matrix<double, Eigen::Dynamic, 15, Eigen::ColMajor, 3 * kStackCorners, 15>;

/// The 15 free entries of the centred map T' (column-major, T'(r, c) at 4c + r, T'(3, 3) = 1
/// moved to the right-hand side) closest to the identity among the least-squares solutions
/// of (p_i - c_p, 1) T' ~ (q_i - c_q, 1): T' = I + D with D of least norm solving
/// M D = b - M vec(I).
template <typename FitMatrix>
Eigen::VectorXd closestToIdentity(const std::vector<Eigen::Vector3d>& p, const std::vector<Eigen::Vector3d>& q,
                                  const Eigen::Vector3d& cp, const Eigen::Vector3d& cq, double rankThreshold,
                                  int& rank) {
  using Column = Eigen::Matrix<double, FitMatrix::RowsAtCompileTime, 1, Eigen::ColMajor, FitMatrix::MaxRowsAtCompileTime, 1>;
  const std::size_t k = p.size();
  const auto rows = static_cast<Eigen::Index>(3 * k);
  FitMatrix M = FitMatrix::Zero(rows, 15);
  Column b = Column::Zero(rows);
  for (std::size_t i = 0; i < k; ++i) {
    const Eigen::Vector3d pc = p[i] - cp;
    const Eigen::Vector3d qc = q[i] - cq;
    const Eigen::Vector4d ph(pc.x(), pc.y(), pc.z(), 1.0);
    for (int j = 0; j < 3; ++j) {
      const Eigen::Index row = static_cast<Eigen::Index>(3 * i + j);
      for (int r = 0; r < 4; ++r) {
        M(row, 4 * j + r) += ph[r];
        const double weightCoefficient = -qc[j] * ph[r];
        if (4 * 3 + r == 15) {
          b[row] -= weightCoefficient;  // T'(3, 3) = 1
        } else {
          M(row, 4 * 3 + r) += weightCoefficient;
        }
      }
    }
  }
  Eigen::Matrix<double, 15, 1> identity = Eigen::Matrix<double, 15, 1>::Zero();
  identity[0] = identity[5] = identity[10] = 1.0;
  Eigen::CompleteOrthogonalDecomposition<FitMatrix> cod;
  cod.setThreshold(rankThreshold);
  cod.compute(M);
  rank = static_cast<int>(cod.rank());
  const Column rhs = b - M * identity;
  return identity + cod.solve(rhs);
}

}  // namespace

std::vector<Eigen::Vector3d> projectOntoBestFitPlane(std::span<const Eigen::Vector3d> points) {
  std::vector<Eigen::Vector3d> projected(points.begin(), points.end());
  if (points.size() < 4) return projected;  // three points are always planar
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const auto& p : points) covariance += (p - centroid) * (p - centroid).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(covariance);
  const Eigen::Vector3d normal = eig.eigenvectors().col(0);
  for (auto& p : projected) p -= normal * (p - centroid).dot(normal);
  return projected;
}

ProjectiveFit fitProjectiveMap(std::span<const Eigen::Vector3d> source, std::span<const Eigen::Vector3d> target,
                               const LocalFitSettings& settings) {
  const std::size_t k = source.size();
  std::vector<Eigen::Vector3d> p(source.begin(), source.end());
  std::vector<Eigen::Vector3d> q(target.begin(), target.end());
  if (settings.projectOntoPlanes) {
    p = projectOntoBestFitPlane(source);
    q = projectOntoBestFitPlane(target);
  }

  // Per-face centring: fit T' between p'_i = p_i - c_p and q'_i = q_i - c_q. The source
  // plane then passes through the origin, so no map with T'(3, 3) = 1 can send every
  // (p'_i, 1) to zero: uncentred, the map n_h r^T built on the homogeneous source plane
  // n_h = (n, -d) collapses the face (all shat_i = 0) and is an exact but degenerate
  // solution whenever more than four corners over-determine the homography. Centred,
  // sum_i (p'_i, 1) = k e_4, so the normalization T'(3, 3) = 1 means "mean reciprocal scale
  // 1", and "closest to the identity" no longer depends on where the face sits.
  Eigen::Vector3d cp = Eigen::Vector3d::Zero();
  Eigen::Vector3d cq = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < k; ++i) {
    cp += p[i];
    cq += q[i];
  }
  if (k > 0) {
    cp /= static_cast<double>(k);
    cq /= static_cast<double>(k);
  }

  // Faces of up to kStackCorners corners (quads, hexagons) fit with matrices on the stack:
  // the same decomposition without the heap, 152k -> 170k quads/s on one core
  // (`plano_bench --benchmark_filter='BM_ProjectiveFits/cpu'`, 2026-12-05). The
  // decomposition itself is most of the rest.
  int rank = 0;
  const Eigen::VectorXd t = k <= kStackCorners
                                ? closestToIdentity<StackFitMatrix>(p, q, cp, cq, settings.rankThreshold, rank)
                                : closestToIdentity<Eigen::MatrixXd>(p, q, cp, cq, settings.rankThreshold, rank);

  ProjectiveFit fit;
  fit.rank = rank;
  Eigen::Matrix4d centred;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      const int index = 4 * c + r;
      centred(r, c) = index == 15 ? 1.0 : t[index];
    }
  }
  // Back to the original coordinates: T = S_p T' S_q^{-1}, with (p, 1) S_p = (p - c_p, 1)
  // and (q - c_q, 1) S_q^{-1} = (q, 1). T keeps T''s scale: its reciprocal scales are T''s,
  // whose mean over the corners is 1. The paper's T(3, 3) = 1 would rescale by the
  // reciprocal scale of the global origin instead, which is tiny on a face whose map sends
  // the origin near its plane at infinity (a face small against its distance from the
  // origin, with a strong perspective part): that face's entries then grew by its inverse
  // (to 884 on an Enneper mesh's first Catmull-Clark level), and with them its weight in
  // the global step's objective (squared) and the ADMM's scales.
  Eigen::Matrix4d Sp = Eigen::Matrix4d::Identity();
  Sp.block<1, 3>(3, 0) = -cp.transpose();
  Eigen::Matrix4d SqInverse = Eigen::Matrix4d::Identity();
  SqInverse.block<1, 3>(3, 0) = cq.transpose();
  fit.map = Sp * centred * SqInverse;

  fit.reciprocalScales.resize(k);
  double squaredResidual = 0.0;
  for (std::size_t i = 0; i < k; ++i) {
    const Eigen::RowVector4d ph(p[i].x(), p[i].y(), p[i].z(), 1.0);
    const Eigen::RowVector4d image = ph * fit.map;
    fit.reciprocalScales[i] = image[3];
    squaredResidual += (image.head<3>() - image[3] * q[i].transpose()).squaredNorm();
  }
  const auto rows = static_cast<Eigen::Index>(3 * k);
  fit.residual = rows > 0 ? std::sqrt(squaredResidual / static_cast<double>(rows)) : 0.0;
  return fit;
}

}  // namespace plano::projective
