#pragma once
// The body shared by the reader fuzz targets. Any input must either be refused with
// plano::Error or give a mesh that (1) passed validation, (2) builds a topology, and
// (3) survives a write/read round trip unchanged. Anything else (a crash, a sanitizer
// report, another exception, a changed round trip) is a bug.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "mesh/Topology.h"

namespace plano::fuzz {

inline int fuzzMesh(const std::uint8_t* data, std::size_t size, MeshFormat format) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  PolygonMesh mesh;
  try {
    mesh = parseMesh(text, format, "fuzz");
  } catch (const Error&) {
    return 0;  // refused with a message: the expected outcome for most inputs
  }
  const MeshTopology topology(mesh.faces, mesh.vertexCount());  // must not throw on a valid mesh
  if (topology.cornerCount() != mesh.faces.cornerCount()) std::abort();
  const PolygonMesh back = parseMesh(formatMesh(mesh, format), format, "round trip");
  if (back.faces != mesh.faces || back.vertices != mesh.vertices) std::abort();
  return 0;
}

}  // namespace plano::fuzz
