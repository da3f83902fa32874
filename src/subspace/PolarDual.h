#pragma once
// The polar dual of a polyhedral mesh (linear-spaces paper, §3 "Dual exploration"): one
// dual vertex per primal face, n / d for the face plane n . x = d (polarity in the unit
// sphere, so the vector to a dual vertex is parallel to the primal face normal), and one
// dual face per interior primal vertex (its fan of faces). The dual of a polyhedral mesh
// is polyhedral, so every linear space applies to it: this explores a mesh through its
// face planes instead of its vertices.
#include "mesh/PolygonMesh.h"

namespace plano::subspace {

struct PolarDualSettings {
  /// A face plane closer to the origin than this times the bounding-box diagonal has its
  /// dual vertex (near) infinity: rejected.
  double originTolerance = 1e-9;
};

/// Dual mesh: #F vertices (dual vertex f belongs to primal face f) and one face per
/// interior primal vertex, in vertex order (boundary vertices have no closed fan and no
/// dual face). Throws Error(BadInput) naming the face whose plane passes through the
/// origin, a degenerate face, or a mesh without interior vertices.
PolygonMesh polarDual(const PolygonMesh& primal, const PolarDualSettings& settings = {});

/// The primal vertices from (possibly edited) dual vertices: vertex v lies on the plane
/// {x : p_f . x = 1} of every incident face f. Each vertex solves its own small system (the
/// sparse system is block diagonal); a vertex with fewer than three independent planes
/// takes the solution closest to its position in `fallback`. Throws Error(BadInput) for
/// size mismatches.
Positions primalFromDual(const FaceList& primalFaces, const Positions& dualVertices, const Positions& fallback);

}  // namespace plano::subspace
