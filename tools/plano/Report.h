#pragma once
// Machine-readable reports (`--report FILE.json`, `plano info --json`). Keys every
// command keeps: command, backend, vertices, faces, planarity {max, mean, p95,
// over_tolerance, tolerance}, seconds, and iterations wherever there are any.
#include <nlohmann/json.hpp>
#include <string>

#include "mesh/Planarity.h"
#include "mesh/PolygonMesh.h"

namespace plano::cli {

nlohmann::json planarityJson(const PlanarityStats& stats);

/// The common keys of a report for a command that produced `mesh`.
nlohmann::json baseReport(const std::string& command, const std::string& backend, const PolygonMesh& mesh,
                          const PlanarityStats& planarity, double seconds);

/// Write a report atomically (pretty-printed); no-op for an empty path.
void writeReport(const std::string& path, const nlohmann::json& report);

}  // namespace plano::cli
