#pragma once
// How every computing command ends, so that a failed computation means the same in each:
// exit code 4 with the reason on stderr, "status", "reason" and "output_written" in the
// report, and the output mesh written only with --keep-partial.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano::cli {

/// --keep-partial, with the same meaning in every command.
void addKeepPartialFlag(CLI::App& app, bool& keepPartial);

/// A mesh the command writes.
struct MeshOutput {
  std::string path;
  const PolygonMesh* mesh = nullptr;
};

struct CommandOutcome {
  std::string status = "ok";  ///< The command's own status word: "converged", "iteration_limit", ...
  std::string failure;        ///< Why the result is not acceptable; empty when it is.
};

/// Write `outputs` when the outcome is a success, or a failure with `keepPartial`, and
/// `report` (completed with status, reason and output_written) to `reportPath` when that
/// is not empty. A mesh with non-finite coordinates counts as a failure and is never
/// written. On failure, throws Error(Numerical) naming the command, the reason and what
/// was written. The run is checked for interruption before anything is written.
void finishCommand(const std::string& command, CommandOutcome outcome, bool keepPartial,
                   const std::vector<MeshOutput>& outputs, nlohmann::json report, const std::string& reportPath);

}  // namespace plano::cli
