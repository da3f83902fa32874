// Exact PLY writer (doubles stored bit for bit in the binary encodings).
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>

#include "mesh/io/PlyFormat.h"
#include "mesh/io/TextWriter.h"

namespace plano::io {
namespace {

template <class T>
void appendBinary(std::string& out, T value, bool bigEndian) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (bigEndian != (std::endian::native == std::endian::big)) std::reverse(bytes, bytes + sizeof(T));
  out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

}  // namespace

std::string formatPly(const PolygonMesh& mesh, PlyEncoding encoding) {
  // uchar counts are what most tools expect; polygons beyond 255 corners need int.
  const bool wideCounts = mesh.faces.maxDegree() > 255;
  std::string out = "ply\nformat ";
  out += encoding == PlyEncoding::Ascii                ? "ascii"
         : encoding == PlyEncoding::BinaryLittleEndian ? "binary_little_endian"
                                                       : "binary_big_endian";
  out += " 1.0\nelement vertex ";
  appendInteger(out, mesh.vertexCount());
  out += "\nproperty double x\nproperty double y\nproperty double z\nelement face ";
  appendInteger(out, mesh.faceCount());
  out += wideCounts ? "\nproperty list int int vertex_indices\n" : "\nproperty list uchar int vertex_indices\n";
  out += "end_header\n";

  if (encoding == PlyEncoding::Ascii) {
    appendVertexAndFaceLines(out, mesh);
    return out;
  }

  const bool big = encoding == PlyEncoding::BinaryBigEndian;
  out.reserve(out.size() + static_cast<std::size_t>(mesh.vertexCount()) * 24 +
              static_cast<std::size_t>(mesh.faceCount()) * 4 + static_cast<std::size_t>(mesh.faces.cornerCount()) * 4);
  for (Index v = 0; v < mesh.vertexCount(); ++v) {
    throwIfCancelledAt(v, "writing the mesh");
    for (int a = 0; a < 3; ++a) appendBinary(out, mesh.vertices(v, a), big);
  }
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    throwIfCancelledAt(f, "writing the mesh");
    if (wideCounts) {
      appendBinary(out, static_cast<std::int32_t>(mesh.faces.degree(f)), big);
    } else {
      appendBinary(out, static_cast<std::uint8_t>(mesh.faces.degree(f)), big);
    }
    for (Index v : mesh.faces[f]) appendBinary(out, static_cast<std::int32_t>(v), big);
  }
  return out;
}

}  // namespace plano::io
