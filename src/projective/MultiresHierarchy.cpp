#include "projective/MultiresHierarchy.h"

#include <string>

#include "core/Error.h"

namespace plano::projective {

SubdivisionHierarchy::SubdivisionHierarchy(const FaceList& base, Index baseVertexCount, int levels) {
  if (levels < 0) throwUsage("subdivision levels must be >= 0 (got " + std::to_string(levels) + ")");
  faces_.push_back(base);
  vertexCounts_.push_back(baseVertexCount);
  if (levels == 0) buildEdgeTopology(base, baseVertexCount);  // same input checks as a refinement
  for (int level = 1; level <= levels; ++level) {
    refinements_.push_back(refineQuads(faces_.back(), vertexCounts_.back()));
    faces_.push_back(refinements_.back().fineFaces);
    vertexCounts_.push_back(refinements_.back().fineVertexCount());
  }
  // Ancestors of the finest faces, from the finest level down: each level's parent map
  // composed with the one above it.
  const Index finestFaces = faces_.back().size();
  finestAncestors_.resize(levels + 1);
  finestAncestors_[levels].resize(finestFaces);
  for (Index f = 0; f < finestFaces; ++f) finestAncestors_[levels][f] = f;
  for (int level = levels - 1; level >= 0; --level) {
    const auto& parent = refinements_[level].parentFace;
    const auto& above = finestAncestors_[level + 1];
    auto& here = finestAncestors_[level];
    here.resize(finestFaces);
    for (Index f = 0; f < finestFaces; ++f) here[f] = parent[above[f]];
  }
}

void SubdivisionHierarchy::checkLevel(int level, const char* what) const {
  if (level < 0 || level > finestLevel()) {
    throwUsage(std::string(what) + ": level " + std::to_string(level) + " is outside the hierarchy (levels 0.." +
               std::to_string(finestLevel()) + ")");
  }
}

const FaceList& SubdivisionHierarchy::faces(int level) const {
  checkLevel(level, "faces");
  return faces_[level];
}

Index SubdivisionHierarchy::vertexCount(int level) const {
  checkLevel(level, "vertex count");
  return vertexCounts_[level];
}

const QuadRefinement& SubdivisionHierarchy::refinement(int level) const {
  if (level < 1 || level > finestLevel()) {
    throwUsage("refinement: level " + std::to_string(level) + " has no refinement step (levels 1.." +
               std::to_string(finestLevel()) + ")");
  }
  return refinements_[level - 1];
}

const std::vector<Index>& SubdivisionHierarchy::ancestorsOfFinestFaces(int level) const {
  checkLevel(level, "ancestors");
  return finestAncestors_[level];
}

Index SubdivisionHierarchy::ancestor(int level, Index face, int coarseLevel) const {
  checkLevel(level, "ancestor");
  checkLevel(coarseLevel, "ancestor");
  if (coarseLevel > level) {
    throwUsage("ancestor: level " + std::to_string(coarseLevel) + " is finer than level " + std::to_string(level));
  }
  if (face < 0 || face >= faces_[level].size()) {
    throwUsage("ancestor: face " + std::to_string(face) + " does not exist on level " + std::to_string(level));
  }
  for (int l = level; l > coarseLevel; --l) face = refinements_[l - 1].parentFace[face];
  return face;
}

Index SubdivisionHierarchy::fineCounterpart(int level, Index vertex) const {
  checkLevel(level, "fine counterpart");
  if (vertex < 0 || vertex >= vertexCounts_[level]) {
    throwUsage("fine counterpart: vertex " + std::to_string(vertex) + " does not exist on level " +
               std::to_string(level));
  }
  return vertex;
}

}  // namespace plano::projective
