#pragma once
// Derived connectivity of a polygon mesh, built once from its faces and kept in flat
// arrays (CSR where a list per element is needed) that solvers and GPU kernels can
// upload as they are: unique edges with the faces on either side, the edge of every
// face corner, face adjacency, vertex-face incidence, boundary loops and the counts
// that describe the surface (Euler characteristic, boundaries, genus, components).
//
// Conventions used throughout:
// - A corner is a (face, local index k) pair; its global id is faces.offsets()[f] + k,
//   the position of the vertex in faces.indices().
// - Corner k of face f "owns" the face edge from its vertex to the next corner's vertex,
//   faces[f][k] -> faces[f][(k + 1) % degree].
// - Edges are numbered in order of first appearance when walking the faces and their
//   corners in order. Side 0 of an edge is the face of that first appearance and the
//   edge's vertex pair (v0, v1) follows that face's direction. Side 1 is the other face,
//   or kNoFace on the boundary. In a consistently oriented mesh side 1 runs v1 -> v0.
// - Boundary loops follow the direction of their faces' edges (a disc whose faces are
//   counter-clockwise seen from +z has a counter-clockwise boundary loop).
//
// The topology requires what every later algorithm relies on and throws Error(BadInput)
// otherwise: vertex indices in [0, vertexCount), faces of >= 3 distinct vertices and edges
// shared by at most two faces. Non-manifold vertices and inconsistent orientation are
// tolerated (counted below) so that Validation can describe them; genus is then undefined.
// Use plano::validate (Validation.h) for a full report of what is wrong with a mesh.
#include <optional>
#include <span>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano {

/// Marks "no face" (the missing side of a boundary edge) and "no component".
inline constexpr Index kNoFace = -1;

/// Counts and invariants of one connected component (faces connected through shared
/// vertices; isolated vertices are not part of any component).
struct ComponentSummary {
  Index vertices = 0;
  Index edges = 0;
  Index faces = 0;
  Index boundaries = 0;           ///< Boundary loops.
  Index eulerCharacteristic = 0;  ///< V - E + F.
  /// chi = 2 - 2g - b for a connected orientable manifold; empty when the component is not
  /// an oriented manifold (non-manifold vertex, inconsistent orientation) or the formula
  /// gives no non-negative integer.
  std::optional<Index> genus;
};

class MeshTopology {
 public:
  MeshTopology() = default;

  /// Build the topology of `faces` over `vertexCount` vertices (isolated vertices allowed).
  /// Throws Error(BadInput) naming the face/edge for an index out of range, a face of
  /// fewer than 3 vertices, a face repeating a vertex, or an edge of more than two faces.
  /// O(corners log corners).
  MeshTopology(const FaceList& faces, Index vertexCount);

  // ---- counts -------------------------------------------------------------------
  Index vertexCount() const { return vertexCount_; }
  Index edgeCount() const { return static_cast<Index>(edgeVertices_.size() / 2); }
  Index faceCount() const { return static_cast<Index>(faceOffsets_.size()) - 1; }
  Index cornerCount() const { return static_cast<Index>(cornerEdge_.size()); }
  Index boundaryEdgeCount() const { return static_cast<Index>(boundaryEdges_.size()); }
  Index boundaryVertexCount() const { return static_cast<Index>(boundaryVertices_.size()); }
  /// Number of boundary loops.
  Index boundaryCount() const { return static_cast<Index>(loopOffsets_.size()) - 1; }
  /// Vertices in no face.
  Index isolatedVertexCount() const { return isolatedVertexCount_; }
  /// V - E + F over the whole mesh (isolated vertices included, each counting 1).
  Index eulerCharacteristic() const { return vertexCount() - edgeCount() + faceCount(); }
  /// Connected components of faces (through shared vertices).
  Index componentCount() const { return static_cast<Index>(components_.size()); }
  /// Sum of the components' genera (the genus for a connected mesh); empty when any
  /// component's genus is undefined (see ComponentSummary::genus) or there is no face.
  std::optional<Index> genus() const;

  // ---- edges --------------------------------------------------------------------
  /// 2 x #E, edge e joins edgeVertices()[2e] -> edgeVertices()[2e + 1] (side 0's direction).
  const std::vector<Index>& edgeVertices() const { return edgeVertices_; }
  /// 2 x #E, the faces on side 0 and side 1 of edge e (side 1 is kNoFace on the boundary).
  const std::vector<Index>& edgeFaces() const { return edgeFaces_; }
  /// 2 x #E, for each side the local corner index k in that face owning the edge
  /// (-1 where the side has no face).
  const std::vector<Index>& edgeCorners() const { return edgeCorners_; }
  Index edgeVertex(Index e, int end) const { return edgeVertices_[2 * e + end]; }
  Index edgeFace(Index e, int side) const { return edgeFaces_[2 * e + side]; }
  Index edgeCorner(Index e, int side) const { return edgeCorners_[2 * e + side]; }
  bool isBoundaryEdge(Index e) const { return edgeFaces_[2 * e + 1] == kNoFace; }

  /// #corners, the edge owned by each corner (global corner id, see the conventions).
  const std::vector<Index>& cornerEdges() const { return cornerEdge_; }
  /// The edge owned by corner k of face f.
  Index faceEdge(Index f, Index k) const { return cornerEdge_[faceOffsets_[f] + k]; }

  /// Edges whose two faces traverse them in the same direction (the mesh is not
  /// consistently oriented there), in increasing order.
  const std::vector<Index>& inconsistentEdges() const { return inconsistentEdges_; }

  // ---- faces --------------------------------------------------------------------
  /// Face adjacency in CSR form: the faces sharing an edge with face f are
  /// faceNeighbors()[faceNeighborOffsets()[f] .. faceNeighborOffsets()[f + 1]), in corner
  /// order, each listed once.
  const std::vector<Index>& faceNeighborOffsets() const { return faceNeighborOffsets_; }
  const std::vector<Index>& faceNeighbors() const { return faceNeighbors_; }
  std::span<const Index> neighborsOfFace(Index f) const;

  // ---- vertices -----------------------------------------------------------------
  /// Vertex-face incidence in CSR form: the faces around vertex v are
  /// vertexFaces()[vertexFaceOffsets()[v] .. vertexFaceOffsets()[v + 1]) in increasing
  /// face order, and vertexFaceCorners() holds, at the same positions, the local corner
  /// index of v in each of those faces.
  const std::vector<Index>& vertexFaceOffsets() const { return vertexFaceOffsets_; }
  const std::vector<Index>& vertexFaces() const { return vertexFaces_; }
  const std::vector<Index>& vertexFaceCorners() const { return vertexFaceCorners_; }
  std::span<const Index> facesOfVertex(Index v) const;
  std::span<const Index> cornersOfVertex(Index v) const;

  /// Number of face fans around each vertex: 1 for a manifold vertex, 0 for an isolated
  /// one, >= 2 where separate fans meet at a single vertex (non-manifold vertex).
  const std::vector<Index>& vertexFanCounts() const { return vertexFanCount_; }

  // ---- boundary -----------------------------------------------------------------
  /// Boundary edges in increasing order.
  const std::vector<Index>& boundaryEdges() const { return boundaryEdges_; }
  /// Vertices on a boundary edge, in increasing order.
  const std::vector<Index>& boundaryVertices() const { return boundaryVertices_; }
  /// #V flags: 1 where the vertex lies on a boundary edge.
  const std::vector<unsigned char>& isBoundaryVertex() const { return isBoundaryVertex_; }
  /// Boundary loops in CSR form: loop l visits loopVertices()[loopOffsets()[l] ..
  /// loopOffsets()[l + 1]) in order (the first vertex is not repeated at the end), and
  /// loopEdges() holds, at the same positions, the edge from each vertex to the next.
  /// Loops are always closed (every vertex has an even number of boundary edges). Where
  /// the orientation is inconsistent, some loop edges run against their face's direction.
  const std::vector<Index>& loopOffsets() const { return loopOffsets_; }
  const std::vector<Index>& loopVertices() const { return loopVertices_; }
  const std::vector<Index>& loopEdges() const { return loopEdges_; }
  std::span<const Index> boundaryLoop(Index l) const;

  // ---- components ---------------------------------------------------------------
  /// #F, the component of each face (0-based, components numbered by their first face).
  const std::vector<Index>& faceComponents() const { return faceComponent_; }
  /// #V, the component of each vertex, kNoFace (-1) for an isolated vertex.
  const std::vector<Index>& vertexComponents() const { return vertexComponent_; }
  const std::vector<ComponentSummary>& components() const { return components_; }

 private:
  void buildEdges(const FaceList& faces);
  void buildVertexFaces(const FaceList& faces);
  void buildFaceNeighbors();
  void buildFans();
  void buildBoundary();
  void buildComponents(const FaceList& faces);

  Index vertexCount_ = 0;
  Index isolatedVertexCount_ = 0;
  std::vector<Index> faceOffsets_{0};
  std::vector<Index> edgeVertices_, edgeFaces_, edgeCorners_, cornerEdge_, inconsistentEdges_;
  std::vector<Index> faceNeighborOffsets_{0}, faceNeighbors_;
  std::vector<Index> vertexFaceOffsets_{0}, vertexFaces_, vertexFaceCorners_, vertexFanCount_;
  std::vector<Index> boundaryEdges_, boundaryVertices_;
  std::vector<unsigned char> isBoundaryVertex_;
  std::vector<Index> loopOffsets_{0}, loopVertices_, loopEdges_;
  std::vector<Index> faceComponent_, vertexComponent_;
  std::vector<ComponentSummary> components_;
};

}  // namespace plano
