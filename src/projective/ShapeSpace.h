#pragma once
// The projective shape space of a base polyhedral mesh (projective-maps paper, §3, §3.1).
//
// A deformed mesh is parametrized by one 4x4 projective map A_f per face (row-vector
// convention: (p_i, 1) A_f is proportional to (q_i, 1); the paper normalizes A_f(3, 3) = 1,
// maps fitted by the local step have mean reciprocal scale 1 over their face) and
// per-corner scale factors s_{f,i} with s_{f,i} (p_i, 1) A_f = (q_i, 1) (Eq. 2). Faces of
// any degree >= 3 carry a single map. All maps act on normalized coordinates (see
// Normalization.h); positions are mapped back to world coordinates on output.
#include <Eigen/Core>
#include <utility>
#include <vector>

#include "compute/Backend.h"
#include "mesh/PolygonMesh.h"
#include "projective/Normalization.h"

namespace plano::projective {

/// One map per face and the reciprocal scale factor shat_{f,i} = 1 / s_{f,i} of every
/// corner, in the FaceList's CSR corner order.
struct FaceMaps {
  std::vector<Eigen::Matrix4d> maps;     ///< #F maps (any scale: positions dehomogenize).
  std::vector<double> reciprocalScales;  ///< #corners, shat = (p_i, 1) A_f[:, 3].
};

class ShapeSpace {
 public:
  /// Takes the base mesh (world coordinates). Throws Error(BadInput) naming the face or
  /// vertex for faces with fewer than three corners, out-of-range or repeated indices in
  /// a face, and non-finite coordinates.
  explicit ShapeSpace(const PolygonMesh& base);

  const FaceList& faces() const { return faces_; }
  Index faceCount() const { return faces_.size(); }
  Index vertexCount() const { return static_cast<Index>(basePositions_.rows()); }
  Index cornerCount() const { return faces_.cornerCount(); }

  /// Base vertex positions p_i in normalized coordinates (#V x 3).
  const Positions& basePositions() const { return basePositions_; }
  /// The base mesh in world coordinates.
  const PolygonMesh& baseMesh() const { return base_; }
  const Normalization& normalization() const { return normalization_; }

  /// Face of corner c (corners in CSR order).
  Index cornerFace(Index c) const { return cornerFace_[c]; }
  /// Corners of vertex v: cornersOfVertex[vertexCornerOffsets[v] .. vertexCornerOffsets[v+1]).
  const std::vector<Index>& vertexCornerOffsets() const { return vertexCornerOffsets_; }
  const std::vector<Index>& cornersOfVertex() const { return cornersOfVertex_; }
  /// These tables and each corner's face, as a backend takes them (Backend::mapPositions).
  compute::VertexCorners vertexCorners() const { return {vertexCornerOffsets_, cornersOfVertex_, cornerFace_}; }
  Index vertexDegree(Index v) const { return vertexCornerOffsets_[v + 1] - vertexCornerOffsets_[v]; }
  /// Pairs (f, g), f < g, of faces sharing an edge (the smoothness term of §6.3).
  const std::vector<std::pair<Index, Index>>& adjacentFaces() const { return adjacentFaces_; }

  /// The identity map on every face (the base mesh itself, all scale factors 1).
  FaceMaps identityMaps() const;

  /// Reciprocal scale factors shat_{f,i} = (p_i, 1) A_f[:, 3] induced by maps (#F).
  std::vector<double> inducedReciprocalScales(const std::vector<Eigen::Matrix4d>& maps) const;

  /// Vertex positions from maps (Eq. 2): every corner image (p_i, 1) A_f is
  /// dehomogenized per face, and a vertex takes the mean of its corner images over the
  /// faces sharing it (the images agree exactly when the maps are compatible).
  /// Isolated vertices keep their base position. Normalized coordinates, #V x 3.
  /// Throws Error(Numerical) when a corner image lies at infinity (weight ~ 0).
  Positions normalizedPositions(const std::vector<Eigen::Matrix4d>& maps) const;
  /// The same in world coordinates.
  Positions positions(const std::vector<Eigen::Matrix4d>& maps) const {
    return normalization_.toWorld(normalizedPositions(maps));
  }

  /// Largest distance (normalized units) between a corner image of a vertex and the
  /// vertex's mean position: 0 for compatible maps.
  double maxCornerDisagreement(const std::vector<Eigen::Matrix4d>& maps) const;

 private:
  PolygonMesh base_;
  FaceList faces_;
  Normalization normalization_;
  Positions basePositions_;
  std::vector<Index> cornerFace_;
  std::vector<Index> vertexCornerOffsets_;
  std::vector<Index> cornersOfVertex_;
  std::vector<std::pair<Index, Index>> adjacentFaces_;
};

/// Homogeneous row (p, 1) of a normalized position.
inline Eigen::RowVector4d homogeneous(const Eigen::RowVector3d& p) { return {p.x(), p.y(), p.z(), 1.0}; }

}  // namespace plano::projective
