#pragma once
// Topology of a subdivision hierarchy M_0 (base) ... M_n (finest) built by repeated trivial
// quad refinement (QuadRefinement.h), with the bookkeeping that multi-resolution editing
// needs (projective-maps paper, §6): the "ancestor" on every coarser level of each finest
// face (its "progeny" are the fine faces with that ancestor) and the fine counterpart of
// each coarse vertex. Positions live elsewhere (PqSubdivision), so one hierarchy serves
// every scheme and every deformation of the same mesh.
#include <vector>

#include "mesh/PolygonMesh.h"
#include "projective/QuadRefinement.h"

namespace plano::projective {

class SubdivisionHierarchy {
 public:
  /// Refine `base` (over `baseVertexCount` vertices) `levels` times (levels >= 0).
  /// Throws Error(Usage) for negative levels and Error(BadInput) as refineQuads does.
  SubdivisionHierarchy(const FaceList& base, Index baseVertexCount, int levels);

  /// Number of levels n, so that there are n + 1 meshes M_0 ... M_n.
  int finestLevel() const { return static_cast<int>(faces_.size()) - 1; }
  const FaceList& faces(int level) const;
  Index vertexCount(int level) const;
  /// Refinement step from level - 1 to level (1 <= level <= finestLevel()).
  const QuadRefinement& refinement(int level) const;

  /// For every face of the finest level, its ancestor on `level` (#F_n entries; the
  /// identity on the finest level).
  const std::vector<Index>& ancestorsOfFinestFaces(int level) const;
  /// Ancestor on `coarseLevel` of face `face` of `level` (coarseLevel <= level).
  Index ancestor(int level, Index face, int coarseLevel) const;
  /// The vertex of the finest level that vertex `vertex` of `level` became. Refinement
  /// keeps vertex indices, so this is `vertex` itself; for an interpolating scheme it also
  /// has the same position, for an approximating one it does not (§6.5).
  Index fineCounterpart(int level, Index vertex) const;

 private:
  void checkLevel(int level, const char* what) const;

  std::vector<FaceList> faces_;
  std::vector<Index> vertexCounts_;
  std::vector<QuadRefinement> refinements_;  ///< refinements_[l - 1]: level l - 1 -> l.
  std::vector<std::vector<Index>> finestAncestors_;
};

}  // namespace plano::projective
