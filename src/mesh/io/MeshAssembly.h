#pragma once
// Helpers the readers share to turn parsed arrays into a PolygonMesh without trusting the
// counts a file declares: a header may claim a billion vertices in a 50-byte file.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano::io {

/// How many items to reserve for `declared` items when each needs at least
/// `minBytesPerItem` of the `remainingBytes` left: never more than the file can hold.
inline std::size_t boundedReserve(std::int64_t declared, std::size_t remainingBytes, std::size_t minBytesPerItem) {
  if (declared <= 0) return 0;
  return std::min(static_cast<std::size_t>(declared), remainingBytes / std::max<std::size_t>(minBytesPerItem, 1));
}

/// Largest count a mesh can hold (indices are 32-bit).
inline constexpr std::int64_t kMaxCount = std::numeric_limits<Index>::max();

/// Mesh from x0 y0 z0 x1 ... and faces.
inline PolygonMesh assembleMesh(const std::vector<double>& coordinates, FaceList faces) {
  PolygonMesh mesh;
  const auto rows = static_cast<Eigen::Index>(coordinates.size() / 3);
  mesh.vertices = Eigen::Map<const Positions>(coordinates.data(), rows, 3);
  mesh.faces = std::move(faces);
  return mesh;
}

}  // namespace plano::io
