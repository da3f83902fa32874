#pragma once
// Machine-readable reports (`--report FILE.json`, `plano info --json`). Keys every
// command keeps: command, backend, vertices, faces, planarity {max, mean, p95,
// over_tolerance, tolerance}, seconds, and iterations wherever there are any.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "compute/Backend.h"

#include "core/Error.h"
#include "mesh/Planarity.h"
#include "mesh/PolygonMesh.h"
#include "plano/OutputGuard.h"
#include "projective/GlobalStep.h"

namespace plano::cli {

nlohmann::json planarityJson(const PlanarityStats& stats);

/// A global step's ε schedule: [{epsilon, status, iterations}] in the order tried.
nlohmann::json epsilonAttemptsJson(const std::vector<projective::EpsilonAttempt>& attempts);

/// Add `device_transfers` {uploaded_bytes, downloaded_bytes, copies} to an iteration's
/// entry when the backend counted them (a device backend).
void addTransfers(nlohmann::json& entry, const std::optional<compute::DeviceTransfers>& transfers);
/// Add `key`: [{uploaded_bytes, downloaded_bytes, copies}], one per iteration, when the
/// backend counted them.
void addTransferList(nlohmann::json& entry, const std::string& key,
                     const std::vector<std::optional<compute::DeviceTransfers>>& perIteration);

/// The common keys of a report for a command that produced `mesh`.
nlohmann::json baseReport(const std::string& command, const std::string& backend, const PolygonMesh& mesh,
                          const PlanarityStats& planarity, double seconds);

/// The report as pretty-printed JSON text. Bytes that are not UTF-8 (a file name in another
/// encoding) are replaced by U+FFFD: JSON text must be UTF-8, and nlohmann throws on them.
std::string reportText(const nlohmann::json& report);

/// Write a report (reportText) together with the run's other files `with` (OutputFiles: all
/// of them or none); only `with` for an empty path.
void writeReport(const std::string& path, const nlohmann::json& report, OutputFiles with = OutputFiles{});

/// How many reports writeReport has written in this process. A run that wrote its own
/// report (more detailed than the failure report) changes it, so the failure report does
/// not replace that one.
std::size_t reportsWritten();

/// The report of a run that ended before writing its own: command, status
/// ("interrupted", "numerical_failure", "device_failure", "bad_input"), reason (the
/// message) and output_written false.
nlohmann::json failureReport(const std::string& command, const std::string& status, const std::string& reason);

/// The status word of a failure report for an error of this kind.
const char* failureStatus(ErrorKind kind);

}  // namespace plano::cli
