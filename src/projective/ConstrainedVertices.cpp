#include "projective/ConstrainedVertices.h"

namespace plano::projective {

std::vector<Index> constrainedVertices(const PositionalConstraints& constraints) {
  std::vector<Index> vertices = constraints.fixed;
  for (const Handle& h : constraints.handles) vertices.push_back(h.vertex);
  return vertices;
}

Positions constrainedPositions(const PolygonMesh& base, const PositionalConstraints& constraints) {
  Positions at(constraints.fixed.size() + constraints.handles.size(), 3);
  Eigen::Index row = 0;
  for (Index v : constraints.fixed) at.row(row++) = base.vertices.row(v);
  for (const Handle& h : constraints.handles) at.row(row++) = h.position.transpose();
  return at;
}

}  // namespace plano::projective
