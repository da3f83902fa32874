#pragma once
// Reading and writing polygon meshes (OBJ, OFF, PLY). Polygons stay polygons, and vertex
// and face order are preserved. Writes are atomic: the mesh goes to a temporary file in
// the target's folder that is renamed over the target only once complete.
#include <filesystem>
#include <string>

#include "mesh/PolygonMesh.h"

namespace plano {

/// Read a mesh; the format is chosen by the file extension (.obj, .off, .ply).
/// Throws Error(BadInput) naming the file, line and problem for malformed input.
PolygonMesh readMesh(const std::filesystem::path& path);

/// Write a mesh atomically, full double precision; the format is chosen by the extension.
/// Throws Error(Usage) for an unknown extension and Error(BadInput) if the file cannot be
/// written (the target is left untouched).
void writeMesh(const std::filesystem::path& path, const PolygonMesh& mesh);

/// Write `content` to `path` atomically (temporary file in the same folder + rename).
void writeFileAtomically(const std::filesystem::path& path, const std::string& content);

}  // namespace plano
