#pragma once
// Helpers shared by the subspace tests: generic polyhedral meshes and random members of a
// linear space.
#include <Eigen/Geometry>
#include <random>

#include "mesh/Generators.h"
#include "mesh/Planarity.h"
#include "subspace/LinearSpace.h"

namespace plano::test {

/// Image of a mesh under a fixed generic projective map (planar faces stay planar, but
/// every symmetry of a generated mesh is broken: "general position").
inline PolygonMesh projectiveImage(const PolygonMesh& mesh) {
  Eigen::Matrix4d T;
  T << 1.0, 0.13, -0.07, 0.2, 0.05, 0.9, 0.11, -0.1, -0.09, 0.04, 1.1, 0.3, 0.06, -0.05, 0.04, 1.0;
  PolygonMesh out = mesh;
  for (Index v = 0; v < mesh.vertexCount(); ++v) {
    const Eigen::Vector4d h = T * mesh.vertices.row(v).transpose().homogeneous();
    out.vertices.row(v) = h.hnormalized().transpose();
  }
  return out;
}

/// Random coefficients (deterministic) scaled so that the shape N w has the given RMS size.
inline Eigen::VectorXd randomCoefficients(Index dimension, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::VectorXd w(dimension);
  for (Index i = 0; i < dimension; ++i) w[i] = normal(rng);
  return w.normalized();
}

/// Largest per-face planarity (percent, the mesh core's measure) of the mesh with new positions.
inline double maxPlanarity(const PolygonMesh& topology, const Positions& X) {
  PolygonMesh m{X, topology.faces};
  return planarityStats(m).max;
}

}  // namespace plano::test
