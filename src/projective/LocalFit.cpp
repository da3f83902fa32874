#include "projective/LocalFit.h"

#include <Eigen/Dense>
#include <cmath>

namespace plano::projective {

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

  // Unknown vector: the 16 entries of T in column-major order, T(r, c) at 4c + r, without
  // T(3, 3) (index 15), which is fixed to 1 and moves to the right-hand side.
  const Eigen::Index rows = static_cast<Eigen::Index>(3 * k);
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(rows, 15);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(rows);
  for (std::size_t i = 0; i < k; ++i) {
    const Eigen::Vector4d ph(p[i].x(), p[i].y(), p[i].z(), 1.0);
    for (int j = 0; j < 3; ++j) {
      const Eigen::Index row = static_cast<Eigen::Index>(3 * i + j);
      for (int r = 0; r < 4; ++r) {
        M(row, 4 * j + r) += ph[r];
        const double weightCoefficient = -q[i][j] * ph[r];
        if (4 * 3 + r == 15) {
          b[row] -= weightCoefficient;  // T(3, 3) = 1
        } else {
          M(row, 4 * 3 + r) += weightCoefficient;
        }
      }
    }
  }

  // Closest to the identity: T = I + D with D of least norm solving M D = b - M vec(I).
  Eigen::VectorXd identity = Eigen::VectorXd::Zero(15);
  identity[0] = identity[5] = identity[10] = 1.0;
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
  cod.setThreshold(settings.rankThreshold);
  cod.compute(M);
  const Eigen::VectorXd delta = cod.solve(b - M * identity);
  const Eigen::VectorXd t = identity + delta;

  ProjectiveFit fit;
  fit.rank = static_cast<int>(cod.rank());
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      const int index = 4 * c + r;
      fit.map(r, c) = index == 15 ? 1.0 : t[index];
    }
  }
  fit.residual = rows > 0 ? std::sqrt((M * t - b).squaredNorm() / static_cast<double>(rows)) : 0.0;
  fit.reciprocalScales.resize(k);
  for (std::size_t i = 0; i < k; ++i) {
    const Eigen::Vector4d ph(p[i].x(), p[i].y(), p[i].z(), 1.0);
    fit.reciprocalScales[i] = ph.dot(fit.map.col(3));
  }
  return fit;
}

}  // namespace plano::projective
