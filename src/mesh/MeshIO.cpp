#include "mesh/MeshIO.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "core/DeferredSignals.h"
#include "core/Error.h"
#include "core/StagedFile.h"
#include "mesh/io/ObjFormat.h"
#include "mesh/io/OffFormat.h"
#include "mesh/io/PlyFormat.h"

namespace plano {
namespace {

std::string readWholeFile(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throwBadInput(path.string() + ": no such file");
  if (std::filesystem::is_directory(status)) throwBadInput(path.string() + ": is a directory, not a mesh file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throwBadInput(path.string() + ": cannot be opened for reading");
  std::string data;
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size > 0) {
    data.resize(static_cast<std::size_t>(size));
    in.read(data.data(), size);
    if (in.gcount() != size) throwBadInput(path.string() + ": read error");
  } else {
    // Not seekable (a pipe, /dev/stdin): read to the end.
    data.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return data;
}

/// A mesh whose file content would not read back as the same mesh is refused.
void requireWritable(const std::filesystem::path& path, const PolygonMesh& mesh) {
  for (Index v = 0; v < mesh.vertexCount(); ++v) {
    if (!mesh.vertices.row(v).allFinite()) {
      throwBadInput(path.string() + ": cannot write: vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
  }
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    for (Index v : mesh.faces[f]) {
      if (v < 0 || v >= mesh.vertexCount()) {
        throwBadInput(path.string() + ": cannot write: face " + std::to_string(f) + " has vertex index " +
                      std::to_string(v) + " out of range [0, " + std::to_string(mesh.vertexCount()) + ")");
      }
    }
  }
}

}  // namespace

MeshFormat meshFormatFromPath(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".off") return MeshFormat::Off;
  if (ext == ".ply") return MeshFormat::Ply;
  throwUsage(path.string() + ": unknown mesh format '" + ext + "' (use .obj, .off or .ply)");
}

PolygonMesh parseMesh(std::string_view data, MeshFormat format, const std::string& source,
                      const ReadOptions& options) {
  if (data.empty()) throwBadInput(source + ": file is empty");
  if (std::all_of(data.begin(), data.end(), [](char c) { return std::isspace(static_cast<unsigned char>(c)); })) {
    throwBadInput(source + ": file contains only whitespace");
  }
  PolygonMesh mesh;
  switch (format) {
    case MeshFormat::Obj: mesh = io::parseObj(data, source, options.warnings); break;
    case MeshFormat::Off: mesh = io::parseOff(data, source, options.warnings); break;
    case MeshFormat::Ply: mesh = io::parsePly(data, source, options.warnings); break;
  }
  if (mesh.faceCount() == 0) {
    throwBadInput(source + ": no faces (" + std::to_string(mesh.vertexCount()) + " vertices and no polygon)");
  }
  if (options.validate) {
    const ValidationReport report = validate(mesh, options.validation);
    requireValid(report, source);
    if (options.warnings) {
      for (const auto& issue : report.issues) {
        if (issue.severity == Severity::Warning) options.warnings->push_back(source + ": " + issue.message);
      }
    }
  }
  return mesh;
}

PolygonMesh readMesh(const std::filesystem::path& path, const ReadOptions& options) {
  const MeshFormat format = meshFormatFromPath(path);
  const std::string data = readWholeFile(path);
  return parseMesh(data, format, path.string(), options);
}

std::string formatMesh(const PolygonMesh& mesh, MeshFormat format, const WriteOptions& options) {
  switch (format) {
    case MeshFormat::Obj: return io::formatObj(mesh);
    case MeshFormat::Off: return io::formatOff(mesh);
    case MeshFormat::Ply: return io::formatPly(mesh, options.plyEncoding);
  }
  return {};
}

void writeMesh(const std::filesystem::path& path, const PolygonMesh& mesh, const WriteOptions& options) {
  const MeshFormat format = meshFormatFromPath(path);
  requireWritable(path, mesh);
  writeFileAtomically(path, formatMesh(mesh, format, options));
}

void writeFileAtomically(const std::filesystem::path& path, const std::string& content) {
  const DeferredSignals deferred;
  const std::filesystem::path target = std::filesystem::absolute(path);
  std::error_code ec;
  if (std::filesystem::is_directory(target, ec)) throwBadInput(path.string() + ": is a directory");
  StagedFile file(target, path.string());
  file.write(content);
  file.commit();
}

}  // namespace plano
