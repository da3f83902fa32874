#include "subspace/PolarDual.h"

#include <Eigen/Dense>
#include <string>

#include "core/Error.h"
#include "subspace/FaceConstraintBlocks.h"
#include "subspace/SubspaceTopology.h"

namespace plano::subspace {

PolygonMesh polarDual(const PolygonMesh& primal, const PolarDualSettings& settings) {
  const double diagonal = boundingBoxDiagonal(primal.vertices);
  const VertexFans fans = computeVertexFans(primal.faces, primal.vertexCount());
  PolygonMesh dual;
  dual.vertices.resize(primal.faceCount(), 3);
  for (Index f = 0; f < primal.faceCount(); ++f) {
    const FaceFrame frame = fitFaceFrame(primal.vertices, primal.faces[f], f);
    const double d = frame.normal.dot(frame.centroid);
    if (!(std::abs(d) > settings.originTolerance * diagonal)) {
      throwBadInput("face " + std::to_string(f) +
                    ": its plane passes through the origin, so its polar dual vertex is at infinity (translate the mesh)");
    }
    dual.vertices.row(f) = (frame.normal / d).transpose();
  }
  for (Index v = 0; v < primal.vertexCount(); ++v) {
    if (!fans.closed[v]) continue;
    // The fan runs against the primal orientation; reversing it keeps dual(dual(M)) = M
    // with the same orientation.
    std::vector<Index> face(fans.faces[v].rbegin(), fans.faces[v].rend());
    dual.faces.addFace(face);
  }
  if (dual.faces.empty()) throwBadInput("polar dual: the mesh has no interior vertex, so the dual has no face");
  return dual;
}

Positions primalFromDual(const FaceList& primalFaces, const Positions& dualVertices, const Positions& fallback) {
  if (dualVertices.rows() != primalFaces.size()) {
    throwBadInput("primal from dual: " + std::to_string(dualVertices.rows()) + " dual vertices for " +
                  std::to_string(primalFaces.size()) + " primal faces");
  }
  const Index nv = static_cast<Index>(fallback.rows());
  std::vector<std::vector<Index>> incident(static_cast<std::size_t>(nv));
  for (Index f = 0; f < primalFaces.size(); ++f)
    for (Index v : primalFaces[f]) {
      if (v < 0 || v >= nv) throwBadInput("primal from dual: face " + std::to_string(f) + " refers to vertex " + std::to_string(v));
      incident[v].push_back(f);
    }
  Positions X = fallback;
  for (Index v = 0; v < nv; ++v) {
    if (incident[v].empty()) continue;
    const Eigen::Index m = static_cast<Eigen::Index>(incident[v].size());
    Eigen::MatrixXd A(m, 3);
    for (Eigen::Index i = 0; i < m; ++i) A.row(i) = dualVertices.row(incident[v][i]);
    const Eigen::Vector3d x0 = fallback.row(v).transpose();
    // Minimum-norm correction: x = x0 + A^+ (1 - A x0).
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(A);
    cod.setThreshold(1e-10);
    const Eigen::Vector3d x = x0 + cod.solve(Eigen::VectorXd::Ones(m) - A * x0);
    X.row(v) = x.transpose();
  }
  return X;
}

}  // namespace plano::subspace
