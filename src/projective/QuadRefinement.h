#pragma once
// Trivial quad refinement of a polygon mesh (projective-maps paper, §5): every k-gon is
// split into k quads by connecting its mid-edge points to its mid-face point, the
// "standard quad-refinement step used by primal subdivision methods". The topology is
// computed once (refineQuads) and reused by every subdivision scheme and by the
// multi-resolution hierarchy; positions are a separate step.
//
// Layout of the fine mesh, which the hierarchy and the schemes rely on:
//   fine vertices  [0, V)          the coarse vertices, same indices;
//                  [V, V + E)      one edge point per coarse edge, in EdgeTopology order;
//                  [V + E, V+E+F)  one face point per coarse face, in face order;
//   fine faces     one per coarse corner, in the coarse FaceList's CSR order: the quad of
//                  corner i of face f is (v_i, edge point of (v_i, v_i+1), face point of f,
//                  edge point of (v_i-1, v_i)); it keeps the coarse face's orientation.
#include <array>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano::projective {

/// Edges of an oriented 2-manifold polygon mesh (with or without boundary).
struct EdgeTopology {
  /// #E edges as vertex pairs (a, b) with a < b.
  std::vector<std::array<Index, 2>> edges;
  /// Per corner (CSR order of the FaceList): the edge from that corner to the next one.
  std::vector<Index> cornerEdge;
  /// Per edge: the corners (CSR indices) whose outgoing side is this edge; the second is
  /// -1 for a boundary edge. The first one is the corner of the lower-numbered face.
  std::vector<std::array<Index, 2>> edgeCorners;
  /// Per corner: the face it belongs to.
  std::vector<Index> cornerFace;

  Index edgeCount() const { return static_cast<Index>(edges.size()); }
  bool isBoundary(Index e) const { return edgeCorners[e][1] < 0; }
};

/// Edge connectivity of `faces` over `vertexCount` vertices.
/// Throws Error(BadInput) naming the face, edge or vertex for: a vertex index out of range,
/// a face with fewer than 3 corners or a repeated vertex, an edge shared by more than two
/// faces (non-manifold), two faces traversing a shared edge in the same direction
/// (inconsistent orientation).
EdgeTopology buildEdgeTopology(const FaceList& faces, Index vertexCount);

/// Topology of one trivial refinement step (layout in the file comment).
struct QuadRefinement {
  Index coarseVertexCount = 0;
  Index coarseFaceCount = 0;
  EdgeTopology coarseEdges;    ///< Edges of the coarse mesh (edge points follow this order).
  FaceList fineFaces;          ///< All quads; #fine faces = #coarse corners.
  std::vector<Index> parentFace;  ///< Per fine face: the coarse face it was cut from.

  Index edgePoint(Index edge) const { return coarseVertexCount + edge; }
  Index facePoint(Index face) const { return coarseVertexCount + coarseEdges.edgeCount() + face; }
  Index fineVertexCount() const { return coarseVertexCount + coarseEdges.edgeCount() + coarseFaceCount; }
};

/// Topology of the trivial refinement of `coarse` (#coarse corners quads). Throws as
/// buildEdgeTopology does; also throws Error(BadInput) for an empty face list.
QuadRefinement refineQuads(const FaceList& coarse, Index coarseVertexCount);

/// Positions of the trivial refinement: coarse vertices unchanged, mid-edge points, and
/// mid-face points (centroid of the corners). `coarse` is #V x 3; returns #fine V x 3.
Positions trivialRefinementPositions(const QuadRefinement& refinement, const FaceList& coarseFaces,
                                     const Positions& coarse);

}  // namespace plano::projective
