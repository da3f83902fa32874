#include "subspace/SubspaceTopology.h"

#include <algorithm>
#include <string>
#include <unordered_map>

#include "core/Error.h"
#include "mesh/Topology.h"

namespace plano::subspace {
namespace {

std::uint64_t key(Index a, Index b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

std::string edgeName(Index a, Index b) { return "edge (" + std::to_string(a) + ", " + std::to_string(b) + ")"; }

void checkIndices(const FaceList& faces, Index vertexCount) {
  for (Index f = 0; f < faces.size(); ++f) {
    if (faces.degree(f) < 3) throwBadInput("face " + std::to_string(f) + " has fewer than 3 corners");
    for (Index v : faces[f]) {
      if (v < 0 || v >= vertexCount) {
        throwBadInput("face " + std::to_string(f) + " refers to vertex " + std::to_string(v) + " out of range");
      }
    }
  }
}

/// Directed half-edge (a -> b) to the face that owns it.
std::unordered_map<std::uint64_t, Index> halfEdgeOwners(const FaceList& faces) {
  std::unordered_map<std::uint64_t, Index> owner;
  owner.reserve(static_cast<std::size_t>(faces.cornerCount()) * 2);
  for (Index f = 0; f < faces.size(); ++f) {
    const auto face = faces[f];
    const Index k = faces.degree(f);
    for (Index i = 0; i < k; ++i) {
      const Index a = face[i], b = face[(i + 1) % k];
      if (a == b) throwBadInput("face " + std::to_string(f) + " repeats vertex " + std::to_string(a));
      if (!owner.emplace(key(a, b), f).second) {
        throwBadInput(edgeName(a, b) + " is used twice in the same direction (faces " +
                      std::to_string(owner[key(a, b)]) + " and " + std::to_string(f) +
                      "): non-manifold or inconsistently oriented");
      }
    }
  }
  return owner;
}

}  // namespace

SubspaceTopology computeTopology(const FaceList& faces, Index vertexCount) {
  // The counts come from the mesh core's MeshTopology; the subspace algorithms additionally
  // need an oriented manifold, which MeshTopology tolerates (for Validation to describe).
  const MeshTopology mesh(faces, vertexCount);
  if (!mesh.inconsistentEdges().empty()) {
    const Index e = mesh.inconsistentEdges().front();
    throwBadInput(edgeName(mesh.edgeVertex(e, 0), mesh.edgeVertex(e, 1)) +
                  " is used twice in the same direction (faces " + std::to_string(mesh.edgeFace(e, 0)) + " and " +
                  std::to_string(mesh.edgeFace(e, 1)) + "): inconsistently oriented");
  }
  for (Index v = 0; v < vertexCount; ++v) {
    if (mesh.vertexFanCounts()[v] > 1) {
      throwBadInput("vertex " + std::to_string(v) + " joins " + std::to_string(mesh.vertexFanCounts()[v]) +
                    " separate face fans (non-manifold vertex)");
    }
  }
  SubspaceTopology t;
  t.vertices = vertexCount;
  t.faces = faces.size();
  t.corners = faces.cornerCount();
  t.edges.reserve(static_cast<std::size_t>(mesh.edgeCount()));
  for (Index e = 0; e < mesh.edgeCount(); ++e) {
    const Index a = mesh.edgeVertex(e, 0), b = mesh.edgeVertex(e, 1);
    t.edges.push_back({std::min(a, b), std::max(a, b)});
  }
  std::sort(t.edges.begin(), t.edges.end());
  for (Index l = 0; l < mesh.boundaryCount(); ++l) {
    const auto loop = mesh.boundaryLoop(l);
    t.boundaryLoops.emplace_back(loop.begin(), loop.end());
  }
  t.boundaryVertices = mesh.boundaryVertexCount();
  // Isolated vertices count as components of their own, as in V - E + F = 2c - 2g - b.
  t.components = mesh.componentCount() + mesh.isolatedVertexCount();
  const Index euler = t.vertices - t.edgeCount() + t.faces;
  t.genus = (2 * t.components - t.boundaryLoopCount() - euler) / 2;
  return t;
}

VertexFans computeVertexFans(const FaceList& faces, Index vertexCount) {
  checkIndices(faces, vertexCount);
  const auto owner = halfEdgeOwners(faces);
  // For face f and its corner v with successor q: the next face around v is the owner of
  // the half-edge q -> v (the twin of v -> q). Walking backwards uses the predecessor.
  std::vector<Index> anyFace(static_cast<std::size_t>(vertexCount), -1);
  for (Index f = 0; f < faces.size(); ++f)
    for (Index v : faces[f]) anyFace[v] = f;
  auto cornerOf = [&](Index f, Index v) {
    const auto face = faces[f];
    for (Index i = 0; i < faces.degree(f); ++i)
      if (face[i] == v) return i;
    return Index(-1);
  };
  auto nextFace = [&](Index f, Index v) {
    const Index k = faces.degree(f);
    const Index q = faces[f][(cornerOf(f, v) + 1) % k];
    const auto it = owner.find(key(q, v));
    return it == owner.end() ? Index(-1) : it->second;
  };
  auto previousFace = [&](Index f, Index v) {
    const Index k = faces.degree(f);
    const Index p = faces[f][(cornerOf(f, v) + k - 1) % k];
    const auto it = owner.find(key(v, p));
    return it == owner.end() ? Index(-1) : it->second;
  };

  VertexFans fans;
  fans.faces.resize(static_cast<std::size_t>(vertexCount));
  fans.closed.assign(static_cast<std::size_t>(vertexCount), false);
  for (Index v = 0; v < vertexCount; ++v) {
    if (anyFace[v] < 0) continue;
    // Rewind to the first face of an open fan, so that the fan is one contiguous run.
    Index first = anyFace[v];
    for (Index steps = 0;; ++steps) {
      const Index p = previousFace(first, v);
      if (p < 0) break;
      if (p == anyFace[v] || steps > faces.size()) {
        first = anyFace[v];
        fans.closed[v] = true;
        break;
      }
      first = p;
    }
    Index f = first;
    do {
      fans.faces[v].push_back(f);
      f = nextFace(f, v);
    } while (f >= 0 && f != first && static_cast<Index>(fans.faces[v].size()) <= faces.size());
  }
  return fans;
}

}  // namespace plano::subspace
