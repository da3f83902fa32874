#pragma once
// Host-side checks of the data a kernel will index with. A shader reading outside a
// buffer is undefined behaviour on the device (a crash or a lost device at best), so
// every face list is checked before upload; the scan is cheap next to the upload itself.
#include <string>

#include "mesh/PolygonMesh.h"

namespace plano::vk {

/// Throws Error(BadInput) naming the face (and corner) when a face has fewer than three
/// corners or a corner index outside [0, vertexCount). `operation` prefixes the message.
void checkFaces(const FaceList& faces, Index vertexCount, const std::string& operation);

/// Throws Error(Device) when a per-face kernel's whole-mesh bindings (the positions,
/// #V x 3 doubles, or the corner indices) exceed one storage binding of `maxStorageBufferRange`
/// bytes: such a mesh is for the CPU backend.
void checkMeshFitsOneBinding(const FaceList& faces, Index vertexCount, std::size_t maxStorageBufferRange);

}  // namespace plano::vk
