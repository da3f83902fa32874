#pragma once
// The positional rows of the global step from a constraints set: fixed vertices (at their
// base positions) first, then handles (at their prescribed positions).
#include <vector>

#include "mesh/Constraints.h"
#include "mesh/PolygonMesh.h"

namespace plano::projective {

/// Fixed vertices, then handle vertices, in the order of `constraints`.
std::vector<Index> constrainedVertices(const PositionalConstraints& constraints);

/// #constrained x 3 world positions in the order of constrainedVertices: base positions of
/// the fixed vertices, then the handle positions.
Positions constrainedPositions(const PolygonMesh& base, const PositionalConstraints& constraints);

}  // namespace plano::projective
