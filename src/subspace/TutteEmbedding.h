#pragma once
// Tutte embedding of a disk-topology mesh (linear-spaces paper, §4 "Creating an initial
// PM": a spring embedding of the topology gives a flat, hence polyhedral, first mesh).
// The boundary loop is pinned to a circle (uniform angles) and every interior vertex is
// the average of its neighbours (uniform weights): one sparse SPD solve, on a backend.
#include "compute/Backend.h"
#include "mesh/PolygonMesh.h"

namespace plano::subspace {

struct TutteSettings {
  double radius = 1.0;
};

struct TutteInfo {
  Index boundaryVertices = 0;
  Index interiorVertices = 0;
  Index flippedFaces = 0;  ///< Faces with non-positive signed area (0 for a 3-connected planar graph).
};

/// Positions (#V x 3, z = 0) of the embedding, oriented so that faces are counter-clockwise
/// seen from +z. Throws Error(BadInput) when the mesh is not a single disk (one boundary
/// loop, genus 0, connected) and Error(Numerical) when the solve fails.
/// The interior solve runs on `backend`'s SPD solver (CHOLMOD on the CPU, PCG on Vulkan, to
/// 1e-13 relative residual).
Positions tutteEmbedding(compute::Backend& backend, const FaceList& faces, Index vertexCount,
                         const TutteSettings& settings = {}, TutteInfo* info = nullptr);
/// The same on the CPU reference.
Positions tutteEmbedding(const FaceList& faces, Index vertexCount, const TutteSettings& settings = {},
                         TutteInfo* info = nullptr);

}  // namespace plano::subspace
