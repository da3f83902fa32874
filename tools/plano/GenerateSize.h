#pragma once
// The size of a mesh `plano generate` would build, known before it is built: the least
// resolution of each kind, and its faces and peak memory, so that a resolution whose mesh
// cannot fit is refused with the estimate (core/Memory.h) instead of the process being
// killed once the kernel runs out (hexdome -n 4096 was, at ~24 GiB).
#include <cstdint>
#include <iomanip>
#include <sstream>
#include <string>

#include "core/Error.h"
#include "core/Memory.h"
#include "mesh/PolygonMesh.h"

namespace plano::cli {

struct GeneratedSize {
  Index minimum = 0;   ///< The least -n the kind accepts.
  double faces = 0.0;  ///< Faces at the resolution asked for.
  /// Peak memory per face of `plano generate` (the mesh, the generator's own tables, the
  /// file's text): measured 127-138 B for the quad grids (-n 700-1500), 380-445 B for the
  /// hexagons at -n 400 and ~510 B at -n 4096 (the generator's std::map), rounded up.
  double bytesPerFace = 0.0;
};

/// The size of `kind` at resolution n; nothing (faces 0) for a kind the generators do not
/// know (generate::byName names them in its error).
inline GeneratedSize generatedSize(const std::string& kind, Index n) {
  const double N = static_cast<double>(n);
  if (kind == "translational" || kind == "hypar") return {1, N * N, 200.0};
  if (kind == "revolution") return {2, 2.0 * N * N, 200.0};  // 2n quads around, n along
  // 3n(n+1) hexagons around the centre one. The generator keeps every corner in a std::map.
  if (kind == "hexdome" || kind == "hexplane") return {0, 1.0 + 3.0 * N * (N + 1.0), 600.0};
  if (kind == "cube") return {0, 6.0, 0.0};
  if (kind == "dodecahedron") return {0, 12.0, 0.0};
  return {};
}

/// Throw Error(Usage) when n is below the kind's least resolution, naming n as given, and
/// OutOfMemory (exit 4) with the estimate when the mesh cannot fit in `limit` bytes (0: the
/// memory available, core/Memory.h).
inline void requireGeneratable(const std::string& kind, Index n, std::uint64_t limit = 0) {
  const GeneratedSize size = generatedSize(kind, n);
  if (n < size.minimum) {
    throwUsage("generate " + kind + ": -n must be at least " + std::to_string(size.minimum) + " (got " +
               std::to_string(n) + ")");
  }
  std::ostringstream what;
  what << "generating " << kind << " -n " << n << " (" << std::fixed << std::setprecision(0) << size.faces
       << " faces)";
  requireMemory(size.faces * size.bytesPerFace, what.str(), limit);
}

}  // namespace plano::cli
