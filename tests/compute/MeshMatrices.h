#pragma once
// Sparse test matrices built from generated meshes.
#include "compute/Backend.h"
#include "mesh/PolygonMesh.h"

namespace plano::test {

/// Graph Laplacian of the mesh's edges (uniform weights) plus `shift` on the diagonal and
/// a weight of 100 on every `pinEvery`-th vertex (like positional constraints): symmetric
/// positive definite, #V x #V, compressed.
compute::SparseMatrix laplacianLikeSpd(const PolygonMesh& mesh, double shift, Index pinEvery = 97);

/// A random rows x cols sparse matrix with about perRow non-zeros per row (deterministic).
compute::SparseMatrix randomSparse(Index rows, Index cols, int perRow, unsigned seed);

}  // namespace plano::test
