#include "projective/QuadRefinement.h"

#include <algorithm>
#include <cstdint>
#include <string>

#include "core/Error.h"

namespace plano::projective {
namespace {

std::string edgeName(Index a, Index b) {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "(" + std::to_string(a).
  std::string name = "(";
  name += std::to_string(a);
  name += ", ";
  name += std::to_string(b);
  name += ')';
  return name;
}

void checkFaces(const FaceList& faces, Index vertexCount) {
  for (Index f = 0; f < faces.size(); ++f) {
    const auto face = faces[f];
    if (face.size() < 3) {
      throwBadInput("face " + std::to_string(f) + " has " + std::to_string(face.size()) + " corners (at least 3 needed)");
    }
    for (std::size_t i = 0; i < face.size(); ++i) {
      if (face[i] < 0 || face[i] >= vertexCount) {
        throwBadInput("face " + std::to_string(f) + " refers to vertex " + std::to_string(face[i]) + ", but the mesh has " +
                      std::to_string(vertexCount) + " vertices");
      }
      for (std::size_t j = 0; j < i; ++j) {
        if (face[i] == face[j]) {
          throwBadInput("face " + std::to_string(f) + " visits vertex " + std::to_string(face[i]) + " twice");
        }
      }
    }
  }
}

}  // namespace

EdgeTopology buildEdgeTopology(const FaceList& faces, Index vertexCount) {
  checkFaces(faces, vertexCount);
  const Index corners = faces.cornerCount();
  EdgeTopology topology;
  topology.cornerFace.resize(corners);
  topology.cornerEdge.assign(corners, -1);

  // Sort the corner sides by their undirected edge key: equal keys are the sides shared
  // by neighbouring faces. Sorting scales to millions of corners without a hash map.
  struct Side {
    std::uint64_t key;
    Index corner;
  };
  std::vector<Side> sides(corners);
  const auto& offsets = faces.offsets();
  const auto& indices = faces.indices();
  for (Index f = 0; f < faces.size(); ++f) {
    const Index begin = offsets[f];
    const Index degree = offsets[f + 1] - begin;
    for (Index i = 0; i < degree; ++i) {
      const Index a = indices[begin + i];
      const Index b = indices[begin + (i + 1) % degree];
      const auto lo = static_cast<std::uint64_t>(std::min(a, b));
      const auto hi = static_cast<std::uint64_t>(std::max(a, b));
      sides[begin + i] = {(lo << 32) | hi, begin + i};
      topology.cornerFace[begin + i] = f;
    }
  }
  std::sort(sides.begin(), sides.end(),
            [](const Side& x, const Side& y) { return x.key < y.key || (x.key == y.key && x.corner < y.corner); });

  auto head = [&](Index corner) { return indices[corner]; };
  topology.edges.reserve(corners / 2 + 1);
  topology.edgeCorners.reserve(corners / 2 + 1);
  for (std::size_t s = 0; s < sides.size();) {
    std::size_t end = s + 1;
    while (end < sides.size() && sides[end].key == sides[s].key) ++end;
    const auto a = static_cast<Index>(sides[s].key >> 32);
    const auto b = static_cast<Index>(sides[s].key & 0xffffffffu);
    if (end - s > 2) {
      throwBadInput("edge " + edgeName(a, b) + " is shared by " + std::to_string(end - s) +
                    " faces (non-manifold; at most 2 allowed)");
    }
    const Index first = sides[s].corner;
    const Index second = end - s == 2 ? sides[s + 1].corner : -1;
    if (second >= 0 && head(first) == head(second)) {
      throwBadInput("faces " + std::to_string(topology.cornerFace[first]) + " and " +
                    std::to_string(topology.cornerFace[second]) + " traverse edge " + edgeName(a, b) +
                    " in the same direction (inconsistent orientation)");
    }
    const auto e = static_cast<Index>(topology.edges.size());
    topology.edges.push_back({a, b});
    topology.edgeCorners.push_back({first, second});
    topology.cornerEdge[first] = e;
    if (second >= 0) topology.cornerEdge[second] = e;
    s = end;
  }
  return topology;
}

QuadRefinement refineQuads(const FaceList& coarse, Index coarseVertexCount) {
  if (coarse.empty()) throwBadInput("cannot refine a mesh without faces");
  QuadRefinement refinement;
  refinement.coarseVertexCount = coarseVertexCount;
  refinement.coarseFaceCount = coarse.size();
  refinement.coarseEdges = buildEdgeTopology(coarse, coarseVertexCount);
  const auto& cornerEdge = refinement.coarseEdges.cornerEdge;

  const Index corners = coarse.cornerCount();
  refinement.fineFaces.reserve(static_cast<std::size_t>(corners), static_cast<std::size_t>(corners) * 4);
  refinement.parentFace.resize(corners);
  const auto& offsets = coarse.offsets();
  const auto& indices = coarse.indices();
  for (Index f = 0; f < coarse.size(); ++f) {
    const Index begin = offsets[f];
    const Index degree = offsets[f + 1] - begin;
    const Index center = refinement.facePoint(f);
    for (Index i = 0; i < degree; ++i) {
      const Index previous = begin + (i + degree - 1) % degree;
      refinement.fineFaces.addFace({indices[begin + i], refinement.edgePoint(cornerEdge[begin + i]), center,
                                    refinement.edgePoint(cornerEdge[previous])});
      refinement.parentFace[begin + i] = f;
    }
  }
  return refinement;
}

Positions trivialRefinementPositions(const QuadRefinement& refinement, const FaceList& coarseFaces,
                                     const Positions& coarse) {
  if (coarse.rows() != refinement.coarseVertexCount || coarseFaces.size() != refinement.coarseFaceCount) {
    throwUsage("trivial refinement: the coarse mesh does not match the refinement topology (" +
               std::to_string(coarse.rows()) + " vertices, " + std::to_string(coarseFaces.size()) + " faces; expected " +
               std::to_string(refinement.coarseVertexCount) + " and " + std::to_string(refinement.coarseFaceCount) + ")");
  }
  Positions fine(refinement.fineVertexCount(), 3);
  fine.topRows(coarse.rows()) = coarse;
  const auto& edges = refinement.coarseEdges.edges;
  for (Index e = 0; e < refinement.coarseEdges.edgeCount(); ++e) {
    fine.row(refinement.edgePoint(e)) = 0.5 * (coarse.row(edges[e][0]) + coarse.row(edges[e][1]));
  }
  for (Index f = 0; f < coarseFaces.size(); ++f) {
    Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
    for (const Index v : coarseFaces[f]) sum += coarse.row(v);
    fine.row(refinement.facePoint(f)) = sum / static_cast<double>(coarseFaces.degree(f));
  }
  return fine;
}

}  // namespace plano::projective
