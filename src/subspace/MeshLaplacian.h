#pragma once
// The mesh Laplacian of the eigenshapes and fundamental shapes (linear-spaces paper, §3):
// the uniform graph Laplacian L = D - A over the mesh edges, defined for any polygon mesh.
#include "compute/Backend.h"
#include "mesh/PolygonMesh.h"

namespace plano::subspace {

/// #V x #V symmetric positive semi-definite scalar Laplacian (acts on each coordinate).
compute::SparseMatrix uniformLaplacian(const FaceList& faces, Index vertexCount);

}  // namespace plano::subspace
