#include "mesh/Planarity.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "core/Cancellation.h"

namespace plano {

double quadPlanarity(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d) {
  const Eigen::Vector3d d1 = c - a;
  const Eigen::Vector3d d2 = d - b;
  const double meanDiagonal = 0.5 * (d1.norm() + d2.norm());
  if (!(meanDiagonal > 0.0)) return 0.0;
  const Eigen::Vector3d n = d1.cross(d2);
  const double nn = n.norm();
  double distance;
  // Parallel diagonals (a degenerate quad): the lines' distance is that of b from line ac.
  if (nn <= 1e-14 * d1.norm() * d2.norm()) {
    const double l1 = d1.norm();
    distance = l1 > 0.0 ? (b - a).cross(d1).norm() / l1 : (b - a).norm();
  } else {
    distance = std::abs((b - a).dot(n)) / nn;
  }
  return 100.0 * distance / meanDiagonal;
}

FacePlanarity facePlanarity(const Positions& vertices, std::span<const Index> face) {
  const std::size_t k = face.size();
  FacePlanarity result;
  if (k < 4) return result;
  const std::size_t runs = (k == 4) ? 1 : k;
  double sum = 0.0;
  for (std::size_t i = 0; i < runs; ++i) {
    const double value = quadPlanarity(vertices.row(face[i]).transpose(), vertices.row(face[(i + 1) % k]).transpose(),
                                       vertices.row(face[(i + 2) % k]).transpose(),
                                       vertices.row(face[(i + 3) % k]).transpose());
    sum += value;
    result.max = std::max(result.max, value);
  }
  result.mean = sum / static_cast<double>(runs);
  return result;
}

double planeFitResidual(const Positions& vertices, std::span<const Index> face) {
  const std::size_t k = face.size();
  if (k < 4) return 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (Index v : face) centroid += vertices.row(v).transpose();
  centroid /= static_cast<double>(k);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double edgeSum = 0.0;
  for (std::size_t i = 0; i < k; ++i) {
    const Eigen::Vector3d p = vertices.row(face[i]).transpose() - centroid;
    covariance += p * p.transpose();
    edgeSum += (vertices.row(face[(i + 1) % k]) - vertices.row(face[i])).norm();
  }
  const double meanEdge = edgeSum / static_cast<double>(k);
  if (!(meanEdge > 0.0)) return 0.0;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(covariance);
  const Eigen::Vector3d normal = eig.eigenvectors().col(0);
  double worst = 0.0;
  for (Index v : face) worst = std::max(worst, std::abs((vertices.row(v).transpose() - centroid).dot(normal)));
  return worst / meanEdge;
}

std::vector<double> facePlanarities(const PolygonMesh& mesh) {
  std::vector<double> values(mesh.faceCount());
  for (Index f = 0; f < mesh.faceCount(); ++f) values[f] = facePlanarity(mesh.vertices, mesh.faces[f]).mean;
  return values;
}

PlanarityStats summarizePlanarity(const std::vector<double>& faceValues, double tolerance) {
  PlanarityStats stats;
  stats.tolerance = tolerance;
  if (faceValues.empty()) return stats;
  double sum = 0.0;
  for (double v : faceValues) {
    sum += v;
    stats.max = std::max(stats.max, v);
    if (v > tolerance) ++stats.overTolerance;
  }
  stats.mean = sum / static_cast<double>(faceValues.size());
  std::vector<double> sorted = faceValues;
  const std::size_t rank = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(sorted.size())));
  const std::size_t index = std::min(sorted.size() - 1, rank > 0 ? rank - 1 : 0);
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(index), sorted.end());
  stats.p95 = sorted[index];
  stats.maxRun = stats.max;
  return stats;
}

PlanarityStats planarityStats(const PolygonMesh& mesh, double tolerance) {
  std::vector<double> values(mesh.faceCount());
  double maxRun = 0.0;
  double maxResidual = 0.0;
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    throwIfCancelledAt(f, "measuring planarity");
    const FacePlanarity p = facePlanarity(mesh.vertices, mesh.faces[f]);
    values[f] = p.mean;
    maxRun = std::max(maxRun, p.max);
    maxResidual = std::max(maxResidual, planeFitResidual(mesh.vertices, mesh.faces[f]));
  }
  PlanarityStats stats = summarizePlanarity(values, tolerance);
  stats.maxRun = maxRun;
  stats.maxPlaneFitResidual = maxResidual;
  return stats;
}

}  // namespace plano
