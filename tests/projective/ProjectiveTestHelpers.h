#pragma once
// Helpers shared by the projective tests: projective images of point sets and meshes.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano::test {

/// Image of every row p of `points` under the row-vector projective map H:
/// q = ((p, 1) H)_xyz / ((p, 1) H)_w.
inline Positions applyProjectiveMap(const Positions& points, const Eigen::Matrix4d& H) {
  Positions out(points.rows(), 3);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::RowVector4d h = Eigen::RowVector4d(points(i, 0), points(i, 1), points(i, 2), 1.0) * H;
    out.row(i) = h.head<3>() / h[3];
  }
  return out;
}

/// A perspective map with a moderate projective part (weights stay in [0.7, 1.4] on the
/// unit box around the origin) and a rotation, scaling and translation.
inline Eigen::Matrix4d samplePerspective() {
  Eigen::Matrix4d H;
  H << 0.9, 0.2, -0.1, 0.08,  //
      -0.15, 1.1, 0.05, -0.06,  //
      0.1, -0.05, 0.95, 0.1,  //
      0.3, -0.2, 0.4, 1.0;
  return H;
}

/// A rigid motion of `x` scaled by `scale`, each coordinate then perturbed by normal noise
/// of deviation `noise` (seeded): targets whose ideal maps differ face to face.
inline Positions rotatedScaledAndPerturbed(const Positions& x, double scale, double noise, unsigned seed) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.9, Eigen::Vector3d(0.2, 1.0, -0.5).normalized()).toRotationMatrix();
  Positions out = ((scale * x * R).rowwise() + Eigen::RowVector3d(0.3, -0.7, 1.1)).eval();
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, noise);
  for (Eigen::Index i = 0; i < out.size(); ++i) out.data()[i] += normal(rng);
  return out;
}

}  // namespace plano::test
