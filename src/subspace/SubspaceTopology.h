#pragma once
// Topological counts the subspace algorithms need (edges, boundary loops, genus), taken from
// the mesh core's MeshTopology and checked for an oriented manifold, and the vertex fans in
// rotational order that the polar dual needs (MeshTopology keeps fans unordered).
#include <array>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano::subspace {

struct SubspaceTopology {
  Index vertices = 0;
  Index faces = 0;
  Index corners = 0;
  std::vector<std::array<Index, 2>> edges;      ///< Undirected edges (a < b), each once.
  std::vector<std::vector<Index>> boundaryLoops;  ///< Vertices of each boundary loop, in order.
  Index boundaryVertices = 0;
  Index components = 0;
  Index genus = 0;  ///< From V - E + F = 2c - 2g - b.

  Index edgeCount() const { return static_cast<Index>(edges.size()); }
  Index boundaryLoopCount() const { return static_cast<Index>(boundaryLoops.size()); }
};

/// Counts of a manifold polygon mesh. Throws Error(BadInput) naming the edge or vertex
/// for an edge shared by more than two faces, a repeated directed edge (inconsistent
/// orientation) or a non-manifold boundary vertex, and the face for an out-of-range index.
SubspaceTopology computeTopology(const FaceList& faces, Index vertexCount);

/// For every vertex, its incident faces in rotational order (following the face
/// orientation); `closed[v]` says whether the fan goes all the way around v (interior
/// vertex). Throws like computeTopology.
struct VertexFans {
  std::vector<std::vector<Index>> faces;
  std::vector<bool> closed;
};
VertexFans computeVertexFans(const FaceList& faces, Index vertexCount);

}  // namespace plano::subspace
