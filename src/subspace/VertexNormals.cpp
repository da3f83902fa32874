#include "subspace/VertexNormals.h"

#include <Eigen/Geometry>

namespace plano::subspace {

Eigen::Vector3d vertexNormal(const PolygonMesh& mesh, Index vertex) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    const auto face = mesh.faces[f];
    const Index k = mesh.faces.degree(f);
    bool incident = false;
    for (Index v : face) incident = incident || v == vertex;
    if (!incident) continue;
    for (Index i = 0; i < k; ++i) {
      const Eigen::Vector3d a = mesh.vertices.row(face[i]), b = mesh.vertices.row(face[(i + 1) % k]);
      sum += a.cross(b);
    }
  }
  const double n = sum.norm();
  return n > 0.0 ? Eigen::Vector3d(sum / n) : Eigen::Vector3d::UnitZ();
}

}  // namespace plano::subspace
