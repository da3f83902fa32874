#pragma once
// Vertex normals (sum of the incident faces' Newell normals, i.e. area-weighted), the
// default direction of sparse and fundamental shapes.
#include "mesh/PolygonMesh.h"

namespace plano::subspace {

/// Unit normal at `vertex`; (0, 0, 1) for a vertex with no incident face of non-zero area.
Eigen::Vector3d vertexNormal(const PolygonMesh& mesh, Index vertex);

}  // namespace plano::subspace
