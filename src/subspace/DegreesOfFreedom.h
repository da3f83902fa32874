#pragma once
// Degrees of freedom of a linear space of polyhedral meshes (linear-spaces paper, §2
// "Degrees of freedom"): NDOF = dim null(B), the topological lower bound, and the
// number of free vertices NFV = NDOF / 3.
#include <span>

#include "mesh/PolygonMesh.h"
#include "subspace/FaceSpace.h"

namespace plano::subspace {

/// Lower bound 3 N_v - sum_f (independent equations of face f): the paper's
/// 3(N_v + 3N_f - N_c) (affine), 3N_v - N_c + N_f (parallel), 3N_v - 2(N_c - 2N_f)
/// (vertical), and the per-face sum of those for mixed spaces. May be negative.
Index subspaceLowerBound(const FaceList& faces, Index vertexCount, std::span<const FaceSpace> spaces);

struct DegreesOfFreedom {
  Index dimension = 0;          ///< NDOF = dim null(B), numerical (see BasisSettings::rankTolerance).
  Index lowerBound = 0;         ///< Topological lower bound (can be negative).
  double freeVertices = 0.0;    ///< NFV = NDOF / 3.
  double lowerBoundFreeVertices = 0.0;
};

DegreesOfFreedom degreesOfFreedom(Index dimension, const FaceList& faces, Index vertexCount,
                                  std::span<const FaceSpace> spaces);

}  // namespace plano::subspace
