#include "plano/CommandOutcome.h"

#include <cstdio>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "mesh/Validation.h"
#include "plano/Report.h"

namespace plano::cli {

void addKeepPartialFlag(CLI::App& app, bool& keepPartial) {
  app.add_flag("--keep-partial", keepPartial,
               "Write the result even when the computation failed (exit code 4 all the same); an interrupted run "
               "never writes it");
}

void finishCommand(const std::string& command, CommandOutcome outcome, bool keepPartial,
                   const std::vector<MeshOutput>& outputs, nlohmann::json report, const std::string& reportPath) {
  // A signal that arrived after the last solver iteration still means "do not write".
  throwIfCancelled("writing the results");
  bool writable = true;
  // Beyond this no mesh reader of plano's accepts a coordinate: a file it cannot read again.
  const double largest = ValidationSettings{}.maxCoordinateMagnitude;
  for (const MeshOutput& output : outputs) {
    const bool allFinite = output.mesh->vertices.allFinite();
    if (allFinite && !(output.mesh->vertices.size() > 0 && output.mesh->vertices.cwiseAbs().maxCoeff() > largest)) {
      continue;
    }
    writable = false;
    if (outcome.failure.empty()) {
      outcome.status = allFinite ? "out_of_range" : "non_finite";
      char bound[32];
      std::snprintf(bound, sizeof bound, "%g", largest);
      outcome.failure = allFinite ? std::string("the result has vertex coordinates beyond ") + bound +
                                        ", more than a mesh file may hold (" + output.path + ")"
                                  : "the result has non-finite vertex coordinates (" + output.path + ")";
    }
  }
  const bool succeeded = outcome.failure.empty();
  // Non-finite (or too large) coordinates cannot be written to any mesh format, partial or not.
  const bool write = (succeeded || keepPartial) && writable;
  // The meshes and the report are written together: a file that cannot be written leaves
  // the others as they were (dual's -o is not replaced when --primal fails).
  OutputFiles files(/*interruptible=*/true);
  if (write) {
    for (const MeshOutput& output : outputs) {
      files.add(output.path, formatMesh(*output.mesh, meshFormatFromPath(output.path)));
    }
  }
  report["status"] = outcome.status;
  if (!succeeded) report["reason"] = outcome.failure;
  report["output_written"] = write;
  writeReport(reportPath, report, std::move(files));
  if (succeeded) return;
  std::string written;
  if (write) {
    for (const MeshOutput& output : outputs) written += (written.empty() ? "" : ", ") + output.path;
    written = "; partial result written to " + written;
  } else {
    written = keepPartial ? "; no output written (nothing finite to keep)"
                          : "; no output written (--keep-partial writes the partial result)";
  }
  throwNumerical(command + ": " + outcome.failure + written);
}

}  // namespace plano::cli
