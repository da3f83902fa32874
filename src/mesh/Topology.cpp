#include "mesh/Topology.h"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <string>
#include <utility>

#include "core/Error.h"

namespace plano {
namespace {

/// Union-find with path halving; small and allocation-free after construction.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), Index{0}); }
  Index find(Index x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  /// Returns true when x and y were in different sets.
  bool unite(Index x, Index y) {
    x = find(x);
    y = find(y);
    if (x == y) return false;
    if (y < x) std::swap(x, y);
    parent_[y] = x;  // the smaller id stays the root: deterministic numbering
    return true;
  }

 private:
  std::vector<Index> parent_;
};

std::string faceName(Index f) { return "face " + std::to_string(f); }

/// The preconditions every other part of the topology relies on, checked up front so
/// that the message names the face rather than a symptom further down.
void requireBuildable(const FaceList& faces, Index vertexCount) {
  std::vector<Index> sorted;
  for (Index f = 0; f < faces.size(); ++f) {
    const auto face = faces[f];
    if (face.size() < 3) {
      throwBadInput(faceName(f) + " has " + std::to_string(face.size()) + " vertices (at least 3 needed)");
    }
    for (Index v : face) {
      if (v < 0 || v >= vertexCount) {
        throwBadInput(faceName(f) + ": vertex index " + std::to_string(v) + " out of range [0, " +
                      std::to_string(vertexCount) + ")");
      }
    }
    sorted.assign(face.begin(), face.end());
    std::sort(sorted.begin(), sorted.end());
    const auto repeated = std::adjacent_find(sorted.begin(), sorted.end());
    if (repeated != sorted.end()) {
      throwBadInput(faceName(f) + " repeats vertex " + std::to_string(*repeated));
    }
  }
}

}  // namespace

MeshTopology::MeshTopology(const FaceList& faces, Index vertexCount) : vertexCount_(vertexCount) {
  if (vertexCount < 0) throwBadInput("negative vertex count");
  requireBuildable(faces, vertexCount);
  faceOffsets_ = faces.offsets();
  buildEdges(faces);
  buildVertexFaces(faces);
  buildFaceNeighbors();
  buildFans();
  buildBoundary();
  buildComponents(faces);
}

void MeshTopology::buildEdges(const FaceList& faces) {
  const Index corners = faces.cornerCount();
  const auto& idx = faces.indices();
  std::vector<Index> cornerFace(static_cast<std::size_t>(corners));
  for (Index f = 0; f < faces.size(); ++f) {
    std::fill(cornerFace.begin() + faceOffsets_[f], cornerFace.begin() + faceOffsets_[f + 1], f);
  }
  auto nextCorner = [&](Index c) {
    const Index f = cornerFace[c];
    return c + 1 == faceOffsets_[f + 1] ? faceOffsets_[f] : c + 1;
  };

  // Group the corners by their undirected vertex pair: sorting (key, corner) keeps
  // the corners of one edge together and in increasing corner order.
  std::vector<std::pair<std::uint64_t, Index>> keyed(static_cast<std::size_t>(corners));
  for (Index c = 0; c < corners; ++c) {
    const auto a = static_cast<std::uint64_t>(idx[c]);
    const auto b = static_cast<std::uint64_t>(idx[nextCorner(c)]);
    keyed[c] = {(std::min(a, b) << 32) | std::max(a, b), c};
  }
  std::sort(keyed.begin(), keyed.end());

  // Number edges by first appearance in corner order; remember each group's corners.
  std::vector<Index> groupOfCorner(static_cast<std::size_t>(corners));
  std::vector<Index> groupStart;
  for (std::size_t i = 0; i < keyed.size(); ++i) {
    if (i == 0 || keyed[i].first != keyed[i - 1].first) groupStart.push_back(static_cast<Index>(i));
    groupOfCorner[keyed[i].second] = static_cast<Index>(groupStart.size()) - 1;
  }
  groupStart.push_back(corners);

  const std::size_t edges = groupStart.size() - 1;
  edgeVertices_.assign(2 * edges, 0);
  edgeFaces_.assign(2 * edges, kNoFace);
  edgeCorners_.assign(2 * edges, -1);
  cornerEdge_.assign(static_cast<std::size_t>(corners), -1);
  std::vector<Index> edgeOfGroup(edges, -1);
  Index nextEdge = 0;
  for (Index c = 0; c < corners; ++c) {
    const Index g = groupOfCorner[c];
    if (edgeOfGroup[g] >= 0) {
      cornerEdge_[c] = edgeOfGroup[g];
      continue;
    }
    const Index e = nextEdge++;
    edgeOfGroup[g] = e;
    const Index size = groupStart[g + 1] - groupStart[g];
    if (size > 2) {
      std::string list;
      for (Index i = groupStart[g]; i < groupStart[g + 1]; ++i) {
        list += (list.empty() ? "" : ", ") + std::to_string(cornerFace[keyed[i].second]);
      }
      throwBadInput("edge (" + std::to_string(idx[c]) + ", " + std::to_string(idx[nextCorner(c)]) + ") is shared by " +
                    std::to_string(size) + " faces (" + list + "): non-manifold edge");
    }
    // c is the group's smallest corner, i.e. the edge's first appearance: side 0.
    const Index v0 = idx[c];
    edgeVertices_[2 * e] = v0;
    edgeVertices_[2 * e + 1] = idx[nextCorner(c)];
    edgeFaces_[2 * e] = cornerFace[c];
    edgeCorners_[2 * e] = c - faceOffsets_[cornerFace[c]];
    cornerEdge_[c] = e;
    if (size == 2) {
      const Index other = keyed[groupStart[g] + 1].second;
      edgeFaces_[2 * e + 1] = cornerFace[other];
      edgeCorners_[2 * e + 1] = other - faceOffsets_[cornerFace[other]];
      if (idx[other] == v0) inconsistentEdges_.push_back(e);
    }
  }
  std::sort(inconsistentEdges_.begin(), inconsistentEdges_.end());
}

void MeshTopology::buildVertexFaces(const FaceList& faces) {
  // Counting sort by vertex; walking faces in order keeps each vertex's faces sorted.
  vertexFaceOffsets_.assign(static_cast<std::size_t>(vertexCount_) + 1, 0);
  for (Index v : faces.indices()) ++vertexFaceOffsets_[v + 1];
  std::partial_sum(vertexFaceOffsets_.begin(), vertexFaceOffsets_.end(), vertexFaceOffsets_.begin());
  vertexFaces_.assign(faces.indices().size(), 0);
  vertexFaceCorners_.assign(faces.indices().size(), 0);
  std::vector<Index> fill(vertexFaceOffsets_.begin(), vertexFaceOffsets_.end() - 1);
  for (Index f = 0; f < faces.size(); ++f) {
    const auto face = faces[f];
    for (Index k = 0; k < static_cast<Index>(face.size()); ++k) {
      const Index slot = fill[face[k]]++;
      vertexFaces_[slot] = f;
      vertexFaceCorners_[slot] = k;
    }
  }
  isolatedVertexCount_ = 0;
  for (Index v = 0; v < vertexCount_; ++v) isolatedVertexCount_ += vertexFaceOffsets_[v] == vertexFaceOffsets_[v + 1];
}

void MeshTopology::buildFaceNeighbors() {
  const Index faceCount = this->faceCount();
  faceNeighborOffsets_.assign(static_cast<std::size_t>(faceCount) + 1, 0);
  faceNeighbors_.clear();
  faceNeighbors_.reserve(cornerEdge_.size());
  for (Index f = 0; f < faceCount; ++f) {
    const auto begin = faceNeighbors_.size();
    for (Index c = faceOffsets_[f]; c < faceOffsets_[f + 1]; ++c) {
      const Index e = cornerEdge_[c];
      const Index other = edgeFaces_[2 * e] == f ? edgeFaces_[2 * e + 1] : edgeFaces_[2 * e];
      if (other == kNoFace) continue;
      // Two faces can share more than one edge (e.g. duplicate faces): list them once.
      if (std::find(faceNeighbors_.begin() + static_cast<std::ptrdiff_t>(begin), faceNeighbors_.end(), other) ==
          faceNeighbors_.end()) {
        faceNeighbors_.push_back(other);
      }
    }
    faceNeighborOffsets_[f + 1] = static_cast<Index>(faceNeighbors_.size());
  }
}

void MeshTopology::buildFans() {
  // Each (vertex, face) incidence starts as its own fan; an interior edge joins the
  // incidences of its two faces at both of its end vertices.
  DisjointSets sets(vertexFaces_.size());
  auto incidence = [&](Index v, Index f) {
    const auto first = vertexFaces_.begin() + vertexFaceOffsets_[v];
    const auto last = vertexFaces_.begin() + vertexFaceOffsets_[v + 1];
    return static_cast<Index>(std::lower_bound(first, last, f) - vertexFaces_.begin());
  };
  vertexFanCount_.assign(static_cast<std::size_t>(vertexCount_), 0);
  for (Index v = 0; v < vertexCount_; ++v) vertexFanCount_[v] = vertexFaceOffsets_[v + 1] - vertexFaceOffsets_[v];
  for (Index e = 0; e < edgeCount(); ++e) {
    if (isBoundaryEdge(e)) continue;
    const Index f0 = edgeFaces_[2 * e], f1 = edgeFaces_[2 * e + 1];
    for (int end = 0; end < 2; ++end) {
      const Index v = edgeVertices_[2 * e + end];
      if (sets.unite(incidence(v, f0), incidence(v, f1))) --vertexFanCount_[v];
    }
  }
}

void MeshTopology::buildBoundary() {
  boundaryEdges_.clear();
  isBoundaryVertex_.assign(static_cast<std::size_t>(vertexCount_), 0);
  for (Index e = 0; e < edgeCount(); ++e) {
    if (!isBoundaryEdge(e)) continue;
    boundaryEdges_.push_back(e);
    isBoundaryVertex_[edgeVertices_[2 * e]] = 1;
    isBoundaryVertex_[edgeVertices_[2 * e + 1]] = 1;
  }
  boundaryVertices_.clear();
  for (Index v = 0; v < vertexCount_; ++v) {
    if (isBoundaryVertex_[v]) boundaryVertices_.push_back(v);
  }

  // Boundary edges around each vertex (CSR). Every vertex has an even number of them:
  // each fan around it is either closed or an open path with one boundary edge at
  // each end. So a walk over unused boundary edges can only get stuck where it began,
  // and tracing always yields closed loops.
  std::vector<Index> offsets(static_cast<std::size_t>(vertexCount_) + 1, 0);
  for (Index e : boundaryEdges_) {
    ++offsets[edgeVertices_[2 * e] + 1];
    ++offsets[edgeVertices_[2 * e + 1] + 1];
  }
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  std::vector<Index> incident(static_cast<std::size_t>(offsets.back()));
  std::vector<Index> fill(offsets.begin(), offsets.end() - 1);
  for (Index e : boundaryEdges_) {
    incident[fill[edgeVertices_[2 * e]]++] = e;
    incident[fill[edgeVertices_[2 * e + 1]]++] = e;
  }

  std::vector<unsigned char> used(static_cast<std::size_t>(edgeCount()), 0);
  loopOffsets_.assign(1, 0);
  loopVertices_.clear();
  loopEdges_.clear();
  for (Index start : boundaryEdges_) {
    if (used[start]) continue;
    const Index origin = edgeVertices_[2 * start];
    Index edge = start;
    Index vertex = origin;
    while (true) {
      used[edge] = 1;
      loopVertices_.push_back(vertex);
      loopEdges_.push_back(edge);
      vertex = edgeVertices_[2 * edge] == vertex ? edgeVertices_[2 * edge + 1] : edgeVertices_[2 * edge];
      if (vertex == origin) break;
      // Prefer the edge leaving `vertex` in its face's direction; an edge entering it
      // is only taken where the orientation is inconsistent.
      Index next = -1;
      for (Index i = offsets[vertex]; i < offsets[vertex + 1]; ++i) {
        const Index candidate = incident[i];
        if (used[candidate]) continue;
        if (edgeVertices_[2 * candidate] == vertex) {
          next = candidate;
          break;
        }
        if (next < 0) next = candidate;
      }
      if (next < 0) break;  // unreachable given the parity argument above; never loop forever
      edge = next;
    }
    loopOffsets_.push_back(static_cast<Index>(loopVertices_.size()));
  }
}

void MeshTopology::buildComponents(const FaceList& faces) {
  DisjointSets sets(static_cast<std::size_t>(vertexCount_));
  for (Index f = 0; f < faces.size(); ++f) {
    const auto face = faces[f];
    for (std::size_t k = 1; k < face.size(); ++k) sets.unite(face[0], face[k]);
  }
  // Components are numbered in order of their first face.
  std::vector<Index> componentOfRoot(static_cast<std::size_t>(vertexCount_), kNoFace);
  faceComponent_.assign(static_cast<std::size_t>(faces.size()), kNoFace);
  components_.clear();
  for (Index f = 0; f < faces.size(); ++f) {
    const Index root = sets.find(faces[f][0]);
    if (componentOfRoot[root] == kNoFace) {
      componentOfRoot[root] = static_cast<Index>(components_.size());
      components_.emplace_back();
    }
    faceComponent_[f] = componentOfRoot[root];
    ++components_[faceComponent_[f]].faces;
  }
  vertexComponent_.assign(static_cast<std::size_t>(vertexCount_), kNoFace);
  std::vector<unsigned char> manifold(components_.size(), 1);
  for (Index v = 0; v < vertexCount_; ++v) {
    if (vertexFaceOffsets_[v] == vertexFaceOffsets_[v + 1]) continue;  // isolated
    const Index c = componentOfRoot[sets.find(v)];
    vertexComponent_[v] = c;
    ++components_[c].vertices;
    if (vertexFanCount_[v] > 1) manifold[c] = 0;
  }
  for (Index e = 0; e < edgeCount(); ++e) ++components_[faceComponent_[edgeFaces_[2 * e]]].edges;
  for (Index e : inconsistentEdges_) manifold[faceComponent_[edgeFaces_[2 * e]]] = 0;
  for (Index l = 0; l < boundaryCount(); ++l) {
    ++components_[faceComponent_[edgeFaces_[2 * loopEdges_[loopOffsets_[l]]]]].boundaries;
  }
  for (std::size_t c = 0; c < components_.size(); ++c) {
    auto& s = components_[c];
    s.eulerCharacteristic = s.vertices - s.edges + s.faces;
    const Index twiceGenus = 2 - s.boundaries - s.eulerCharacteristic;
    if (manifold[c] && twiceGenus >= 0 && twiceGenus % 2 == 0) s.genus = twiceGenus / 2;
  }
}

std::optional<Index> MeshTopology::genus() const {
  if (components_.empty()) return std::nullopt;
  Index total = 0;
  for (const auto& c : components_) {
    if (!c.genus) return std::nullopt;
    total += *c.genus;
  }
  return total;
}

std::span<const Index> MeshTopology::neighborsOfFace(Index f) const {
  return {faceNeighbors_.data() + faceNeighborOffsets_[f],
          static_cast<std::size_t>(faceNeighborOffsets_[f + 1] - faceNeighborOffsets_[f])};
}

std::span<const Index> MeshTopology::facesOfVertex(Index v) const {
  return {vertexFaces_.data() + vertexFaceOffsets_[v],
          static_cast<std::size_t>(vertexFaceOffsets_[v + 1] - vertexFaceOffsets_[v])};
}

std::span<const Index> MeshTopology::cornersOfVertex(Index v) const {
  return {vertexFaceCorners_.data() + vertexFaceOffsets_[v],
          static_cast<std::size_t>(vertexFaceOffsets_[v + 1] - vertexFaceOffsets_[v])};
}

std::span<const Index> MeshTopology::boundaryLoop(Index l) const {
  return {loopVertices_.data() + loopOffsets_[l], static_cast<std::size_t>(loopOffsets_[l + 1] - loopOffsets_[l])};
}

}  // namespace plano
