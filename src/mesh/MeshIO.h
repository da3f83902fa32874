#pragma once
// Reading and writing polygon meshes (OBJ, OFF, PLY). Polygons stay polygons, vertex and
// face order are preserved, and coordinates survive a write/read round trip bit for bit.
// Writes are atomic: the mesh goes to a temporary file in the target's folder that is
// renamed over the target only once complete, so a failed or interrupted run never leaves
// a partial file or clobbers the previous one.
//
// The readers are strict streaming parsers of our own (src/mesh/io/), not OpenMesh's:
// OpenMesh builds a half-edge mesh while reading and silently drops the faces it cannot
// add (non-manifold ones), reports a malformed file with a bare "false", and writes
// coordinates with a fixed number of digits. Every defect here is an Error(BadInput)
// naming the file, the line (or byte) and the problem.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "mesh/PolygonMesh.h"
#include "mesh/Validation.h"
#include "mesh/io/PlyFormat.h"

namespace plano {

enum class MeshFormat { Obj, Off, Ply };

/// The format of a file by its extension (.obj, .off, .ply, any case); throws
/// Error(Usage) for anything else.
MeshFormat meshFormatFromPath(const std::filesystem::path& path);

struct ReadOptions {
  /// Run requireValid on the parsed mesh (index ranges, manifoldness, orientation,
  /// degenerate and duplicate faces, ...). Turn off to inspect a defective mesh.
  bool validate = true;
  ValidationSettings validation;
  /// When not null, receives non-fatal findings ("file:line: unknown statement 'xyz'
  /// ignored", "file: vertex 9 is isolated (in no face)").
  std::vector<std::string>* warnings = nullptr;
};

/// Read a mesh; the format is chosen by the file extension. Out: #V x 3 positions and
/// the faces, in file order. Throws Error(Usage) for an unknown extension and
/// Error(BadInput) naming file:line and the problem for a missing, empty, malformed or
/// (with options.validate) invalid mesh, and for a file without faces.
PolygonMesh readMesh(const std::filesystem::path& path, const ReadOptions& options = {});

/// Parse mesh data already in memory (`source` names it in messages), as readMesh.
PolygonMesh parseMesh(std::string_view data, MeshFormat format, const std::string& source,
                      const ReadOptions& options = {});

struct WriteOptions {
  io::PlyEncoding plyEncoding = io::PlyEncoding::BinaryLittleEndian;
};

/// Write a mesh atomically, exact doubles; the format is chosen by the extension.
/// Throws Error(Usage) for an unknown extension and Error(BadInput) for a mesh that
/// cannot be written faithfully (non-finite coordinate, face index out of range) or a
/// file that cannot be written (the target is then left untouched).
void writeMesh(const std::filesystem::path& path, const PolygonMesh& mesh, const WriteOptions& options = {});

/// The file content writeMesh would write for `format`.
std::string formatMesh(const PolygonMesh& mesh, MeshFormat format, const WriteOptions& options = {});

/// Write `content` to `path` atomically (temporary file in the same folder, flushed to
/// disk, then renamed over the target).
void writeFileAtomically(const std::filesystem::path& path, const std::string& content);

}  // namespace plano
