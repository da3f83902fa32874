#include "mesh/MeshIO.h"

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <unistd.h>

#include "core/Error.h"

namespace plano {
namespace {

using OMesh = OpenMesh::PolyMesh_ArrayKernelT<OpenMesh::DefaultTraitsDouble>;

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

void requireKnownExtension(const std::filesystem::path& path) {
  const std::string ext = lowerExtension(path);
  if (ext != ".obj" && ext != ".off" && ext != ".ply") {
    throwUsage(path.string() + ": unknown mesh format '" + ext + "' (use .obj, .off or .ply)");
  }
}

}  // namespace

PolygonMesh readMesh(const std::filesystem::path& path) {
  requireKnownExtension(path);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throwBadInput(path.string() + ": no such file");
  OMesh om;
  if (!OpenMesh::IO::read_mesh(om, path.string())) throwBadInput(path.string() + ": could not be read as a mesh");
  PolygonMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(om.n_vertices()), 3);
  for (auto vh : om.vertices()) {
    const auto& p = om.point(vh);
    mesh.vertices.row(vh.idx()) << p[0], p[1], p[2];
  }
  std::vector<Index> face;
  for (auto fh : om.faces()) {
    face.clear();
    for (auto vh : om.fv_range(fh)) face.push_back(vh.idx());
    mesh.faces.addFace(std::span<const Index>(face));
  }
  return mesh;
}

void writeFileAtomically(const std::filesystem::path& path, const std::string& content) {
  const std::filesystem::path target = std::filesystem::absolute(path);
  std::random_device rd;
  const std::filesystem::path temp =
      target.parent_path() / ("." + target.filename().string() + ".tmp" + std::to_string(getpid()) + "-" +
                              std::to_string(rd()));
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throwBadInput(path.string() + ": cannot write (folder missing or not writable)");
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.flush();
    if (!out) {
      out.close();
      std::filesystem::remove(temp);
      throwBadInput(path.string() + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temp, target, ec);
  if (ec) {
    std::filesystem::remove(temp);
    throwBadInput(path.string() + ": cannot replace file: " + ec.message());
  }
}

void writeMesh(const std::filesystem::path& path, const PolygonMesh& mesh) {
  requireKnownExtension(path);
  OMesh om;
  std::vector<OMesh::VertexHandle> handles(static_cast<std::size_t>(mesh.vertexCount()));
  for (Index v = 0; v < mesh.vertexCount(); ++v) {
    handles[v] = om.add_vertex(OMesh::Point(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2)));
  }
  std::vector<OMesh::VertexHandle> face;
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    face.clear();
    for (Index v : mesh.faces[f]) face.push_back(handles[v]);
    if (!om.add_face(face).is_valid()) {
      throwBadInput(path.string() + ": face " + std::to_string(f) + " cannot be written (non-manifold)");
    }
  }
  std::ostringstream stream;
  if (!OpenMesh::IO::write_mesh(om, stream, lowerExtension(path), OpenMesh::IO::Options::Default, 17)) {
    throwBadInput(path.string() + ": mesh could not be encoded");
  }
  writeFileAtomically(path, stream.str());
}

}  // namespace plano
