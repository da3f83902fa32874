#pragma once
// Number formatting and the shared body of the text mesh writers. Doubles are written as
// the shortest decimal string that reads back to the identical double (std::to_chars),
// which never needs more than 17 significant digits: a write/read round trip is exact.
#include <charconv>
#include <string>

#include "core/Cancellation.h"
#include "mesh/PolygonMesh.h"

namespace plano::io {

inline void appendDouble(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

inline void appendInteger(std::string& out, long long value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

/// The body OFF and ASCII PLY share: a line "x y z" per vertex, then a line
/// "degree v0 v1 ..." per face (0-based indices).
inline void appendVertexAndFaceLines(std::string& out, const PolygonMesh& mesh) {
  for (Index v = 0; v < mesh.vertexCount(); ++v) {
    throwIfCancelledAt(v, "writing the mesh");
    for (int a = 0; a < 3; ++a) {
      if (a) out += ' ';
      appendDouble(out, mesh.vertices(v, a));
    }
    out += '\n';
  }
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    throwIfCancelledAt(f, "writing the mesh");
    appendInteger(out, mesh.faces.degree(f));
    for (Index v : mesh.faces[f]) {
      out += ' ';
      appendInteger(out, v);
    }
    out += '\n';
  }
}

}  // namespace plano::io
