#include "projective/SubdivisionSchemes.h"

#include <array>
#include <string>

#include "core/Error.h"

namespace plano::projective {
namespace {

using Row = Eigen::RowVector3d;

/// What the rules need to know around each coarse vertex.
class VertexStars {
 public:
  VertexStars(const FaceList& faces, const EdgeTopology& topology, Index vertexCount)
      : faces_(faces), topology_(topology), edgeOffsets_(vertexCount + 1, 0), faceCount_(vertexCount, 0) {
    for (const auto& edge : topology.edges) {
      ++edgeOffsets_[edge[0] + 1];
      ++edgeOffsets_[edge[1] + 1];
    }
    for (Index v = 0; v < vertexCount; ++v) edgeOffsets_[v + 1] += edgeOffsets_[v];
    incidentEdges_.resize(edgeOffsets_.back());
    std::vector<Index> fill(edgeOffsets_.begin(), edgeOffsets_.end() - 1);
    for (Index e = 0; e < topology.edgeCount(); ++e) {
      incidentEdges_[fill[topology.edges[e][0]]++] = e;
      incidentEdges_[fill[topology.edges[e][1]]++] = e;
    }
    for (const Index v : faces.indices()) ++faceCount_[v];
  }

  Index valence(Index v) const { return edgeOffsets_[v + 1] - edgeOffsets_[v]; }
  Index faceCount(Index v) const { return faceCount_[v]; }
  std::span<const Index> edges(Index v) const {
    return {incidentEdges_.data() + edgeOffsets_[v], static_cast<std::size_t>(valence(v))};
  }
  Index other(Index e, Index v) const {
    const auto& edge = topology_.edges[e];
    return edge[0] == v ? edge[1] : edge[0];
  }
  /// The boundary edges at v (up to three are reported, to detect non-manifold vertices).
  std::vector<Index> boundaryEdges(Index v) const {
    std::vector<Index> result;
    for (const Index e : edges(v)) {
      if (topology_.isBoundary(e)) result.push_back(e);
    }
    return result;
  }
  /// A vertex on one boundary curve with at least two faces: the curve rules apply.
  bool onBoundaryCurve(Index v) const { return boundaryEdges(v).size() == 2 && faceCount(v) >= 2; }
  bool isInterior(Index v) const { return boundaryEdges(v).empty() && valence(v) > 0; }

  Index vertexOf(Index corner) const { return faces_.indices()[corner]; }
  Index next(Index corner) const {
    const Index f = topology_.cornerFace[corner];
    const Index begin = faces_.offsets()[f];
    return begin + (corner - begin + 1) % faces_.degree(f);
  }
  Index previous(Index corner) const {
    const Index f = topology_.cornerFace[corner];
    const Index begin = faces_.offsets()[f];
    const Index degree = faces_.degree(f);
    return begin + (corner - begin + degree - 1) % degree;
  }
  /// The corner on the other side of the edge leaving `corner` (-1 at the boundary).
  Index across(Index corner) const {
    const auto& pair = topology_.edgeCorners[topology_.cornerEdge[corner]];
    return pair[0] == corner ? pair[1] : pair[0];
  }

  /// At an interior vertex v of valence 4 whose faces form one fan, the neighbour
  /// opposite to w (the continuation of the grid line w -> v); -1 if the star is not such a
  /// regular fan.
  Index oppositeNeighbour(Index v, Index e) const {
    Index corner = -1;
    for (const Index c : topology_.edgeCorners[e]) {
      if (c >= 0 && vertexOf(c) == v) corner = c;
    }
    if (corner < 0) return -1;
    // Rotate around v: the edge entering v in this face, seen from the other side, leaves v.
    auto rotate = [&](Index c) { return across(previous(c)); };
    const Index once = rotate(corner);
    if (once < 0) return -1;
    const Index twice = rotate(once);
    if (twice < 0) return -1;
    // A regular fan closes after four rotations.
    const Index thrice = rotate(twice);
    if (thrice < 0 || rotate(thrice) != corner) return -1;
    return vertexOf(next(twice));
  }

 private:
  const FaceList& faces_;
  const EdgeTopology& topology_;
  std::vector<Index> edgeOffsets_;
  std::vector<Index> incidentEdges_;
  std::vector<Index> faceCount_;
};

void checkMatch(const FaceList& coarseFaces, const Positions& coarse, const QuadRefinement& refinement) {
  if (coarse.rows() != refinement.coarseVertexCount || coarseFaces.size() != refinement.coarseFaceCount ||
      coarseFaces.cornerCount() != refinement.fineFaces.size()) {
    throwUsage("subdivision: the coarse mesh (" + std::to_string(coarse.rows()) + " vertices, " +
               std::to_string(coarseFaces.size()) + " faces) does not match the refinement topology (" +
               std::to_string(refinement.coarseVertexCount) + " vertices, " +
               std::to_string(refinement.coarseFaceCount) + " faces)");
  }
}

Row centroid(const FaceList& faces, const Positions& x, Index f) {
  Row sum = Row::Zero();
  for (const Index v : faces[f]) sum += x.row(v);
  return sum / static_cast<double>(faces.degree(f));
}

Positions catmullClark(const FaceList& faces, const Positions& coarse, const QuadRefinement& refinement) {
  const EdgeTopology& topology = refinement.coarseEdges;
  const VertexStars stars(faces, topology, refinement.coarseVertexCount);
  Positions fine(refinement.fineVertexCount(), 3);

  for (Index f = 0; f < faces.size(); ++f) fine.row(refinement.facePoint(f)) = centroid(faces, coarse, f);
  for (Index e = 0; e < topology.edgeCount(); ++e) {
    const Row mid = 0.5 * (coarse.row(topology.edges[e][0]) + coarse.row(topology.edges[e][1]));
    if (topology.isBoundary(e)) {
      fine.row(refinement.edgePoint(e)) = mid;
    } else {
      const Index f0 = topology.cornerFace[topology.edgeCorners[e][0]];
      const Index f1 = topology.cornerFace[topology.edgeCorners[e][1]];
      fine.row(refinement.edgePoint(e)) =
          0.5 * mid + 0.25 * (fine.row(refinement.facePoint(f0)) + fine.row(refinement.facePoint(f1)));
    }
  }

  // Mean of the adjacent face points, per vertex.
  Positions faceMean = Positions::Zero(coarse.rows(), 3);
  for (Index c = 0; c < faces.cornerCount(); ++c) {
    faceMean.row(faces.indices()[c]) += fine.row(refinement.facePoint(topology.cornerFace[c]));
  }
  for (Index v = 0; v < coarse.rows(); ++v) {
    const Row p = coarse.row(v);
    const auto boundary = stars.boundaryEdges(v);
    if (stars.isInterior(v)) {
      const auto n = static_cast<double>(stars.valence(v));
      Row edgeMean = Row::Zero();
      for (const Index e : stars.edges(v)) edgeMean += 0.5 * (p + coarse.row(stars.other(e, v)));
      edgeMean /= n;
      const Row q = faceMean.row(v) / static_cast<double>(stars.faceCount(v));
      fine.row(v) = (q + 2.0 * edgeMean + (n - 3.0) * p) / n;
    } else if (stars.onBoundaryCurve(v)) {
      fine.row(v) = (coarse.row(stars.other(boundary[0], v)) + 6.0 * p + coarse.row(stars.other(boundary[1], v))) / 8.0;
    } else {
      fine.row(v) = p;  // corner, isolated or non-manifold vertex: kept
    }
  }
  return fine;
}

/// The point continuing the grid line from w through v (see SubdivisionScheme::FourPoint).
Row fourPointGhost(const VertexStars& stars, const Positions& x, Index v, Index e) {
  const Index w = stars.other(e, v);
  const Row p = x.row(v);
  const Row reflected = 2.0 * p - x.row(w);
  if (stars.isInterior(v)) {
    if (stars.valence(v) == 4) {
      const Index opposite = stars.oppositeNeighbour(v, e);
      if (opposite >= 0) return x.row(opposite);
    }
    Row spread = Row::Zero();
    for (const Index edge : stars.edges(v)) spread += x.row(stars.other(edge, v)) - p;
    return reflected + (2.0 / static_cast<double>(stars.valence(v))) * spread;
  }
  if (stars.onBoundaryCurve(v)) {
    const auto boundary = stars.boundaryEdges(v);
    if (boundary[0] == e) return x.row(stars.other(boundary[1], v));
    if (boundary[1] == e) return x.row(stars.other(boundary[0], v));
  }
  return reflected;
}

Positions fourPoint(const FaceList& faces, const Positions& coarse, const QuadRefinement& refinement) {
  const EdgeTopology& topology = refinement.coarseEdges;
  const VertexStars stars(faces, topology, refinement.coarseVertexCount);
  Positions fine(refinement.fineVertexCount(), 3);
  fine.topRows(coarse.rows()) = coarse;

  for (Index e = 0; e < topology.edgeCount(); ++e) {
    const auto [a, b] = topology.edges[e];
    fine.row(refinement.edgePoint(e)) = (9.0 * (coarse.row(a) + coarse.row(b)) - fourPointGhost(stars, coarse, a, e) -
                                         fourPointGhost(stars, coarse, b, e)) /
                                        16.0;
  }

  for (Index f = 0; f < faces.size(); ++f) {
    const Index begin = faces.offsets()[f];
    const Index degree = faces.degree(f);
    auto edgePointOf = [&](Index corner) { return Row(fine.row(refinement.edgePoint(topology.cornerEdge[corner]))); };
    if (degree != 4) {
      Row edgeMean = Row::Zero();
      for (Index i = 0; i < degree; ++i) edgeMean += edgePointOf(begin + i);
      fine.row(refinement.facePoint(f)) = 2.0 * edgeMean / static_cast<double>(degree) - centroid(faces, coarse, f);
      continue;
    }
    // Continuation of the line E_i -> E_(i+2) beyond the edge of corner i: the edge point of
    // the opposite edge in the quad on the other side.
    auto beyond = [&](Index i) -> Row {
      const Index other = stars.across(begin + i);
      const Index otherFace = other >= 0 ? topology.cornerFace[other] : -1;
      if (otherFace < 0 || faces.degree(otherFace) != 4) {
        return 2.0 * edgePointOf(begin + i) - edgePointOf(begin + (i + 2) % 4);
      }
      const Index otherBegin = faces.offsets()[otherFace];
      return edgePointOf(otherBegin + (other - otherBegin + 2) % 4);
    };
    Row sum = Row::Zero();
    for (Index i = 0; i < 2; ++i) {
      sum += (9.0 * (edgePointOf(begin + i) + edgePointOf(begin + i + 2)) - beyond(i) - beyond(i + 2)) / 16.0;
    }
    fine.row(refinement.facePoint(f)) = 0.5 * sum;
  }
  return fine;
}

}  // namespace

SubdivisionScheme parseSubdivisionScheme(const std::string& text) {
  if (text == "catmull-clark") return SubdivisionScheme::CatmullClark;
  if (text == "four-point") return SubdivisionScheme::FourPoint;
  throwUsage("unknown subdivision scheme '" + text + "' (expected catmull-clark or four-point)");
}

const char* toString(SubdivisionScheme scheme) {
  switch (scheme) {
    case SubdivisionScheme::CatmullClark: return "catmull-clark";
    case SubdivisionScheme::FourPoint: return "four-point";
  }
  return "unknown";
}

Positions linearSubdivision(SubdivisionScheme scheme, const FaceList& coarseFaces, const Positions& coarse,
                            const QuadRefinement& refinement) {
  checkMatch(coarseFaces, coarse, refinement);
  switch (scheme) {
    case SubdivisionScheme::CatmullClark: return catmullClark(coarseFaces, coarse, refinement);
    case SubdivisionScheme::FourPoint: return fourPoint(coarseFaces, coarse, refinement);
  }
  throwUsage("unknown subdivision scheme");
}

}  // namespace plano::projective
