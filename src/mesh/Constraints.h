#pragma once
// Positional constraints of deformations (fixed vertices and moved handles), and their
// JSON file format:
//   {"fixed": [i, ...], "handles": [{"vertex": i, "position": [x, y, z]}, ...]}
// with 0-based vertex indices of the input mesh.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "mesh/PolygonMesh.h"

namespace plano {

struct Handle {
  Index vertex = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

struct PositionalConstraints {
  std::vector<Index> fixed;     ///< Vertices that keep their input position.
  std::vector<Handle> handles;  ///< Vertices moved to a prescribed position.

  bool empty() const { return fixed.empty() && handles.empty(); }
};

/// Parse and check constraints against a mesh of `vertexCount` vertices. Throws
/// Error(BadInput) naming the problem: malformed JSON, wrong types, an index out of range,
/// a vertex both fixed and moved (or listed twice), a NaN/Inf position. Unknown keys are
/// reported in `warnings` (when not null) and otherwise ignored.
PositionalConstraints parseConstraints(const nlohmann::json& json, Index vertexCount, std::string* warnings = nullptr,
                                       const std::string& source = "constraints");

/// Read a constraints file (see parseConstraints).
PositionalConstraints readConstraints(const std::filesystem::path& path, Index vertexCount,
                                      std::string* warnings = nullptr);

}  // namespace plano
