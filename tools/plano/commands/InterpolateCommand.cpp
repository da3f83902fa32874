// plano interpolate A B --t T -o OUT: interpolation and extrapolation between two
// polyhedral meshes of the same topology (projective-maps paper, §7.1).
#include <chrono>
#include <sstream>

#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "plano/Command.h"
#include "plano/CommandOutcome.h"
#include "plano/Report.h"
#include "projective/Interpolation.h"

namespace plano::cli {
namespace {

struct InterpolateOptions {
  std::string first;
  std::string second;
  double t = 0.5;
  std::string output;
  std::string report;
  bool keepPartial = false;
};

RunFunction setup(CLI::App& app) {
  auto options = std::make_shared<InterpolateOptions>();
  app.add_option("a", options->first, "Mesh at t = 0")->required();
  app.add_option("b", options->second, "Mesh at t = 1 (same faces as A)")->required();
  app.add_option("--t", options->t, "Parameter: 0 gives A, 1 gives B, other values extrapolate")
      ->required()
      ->check(CLI::Range(-1e6, 1e6));
  app.add_option("-o,--output", options->output, "Output mesh file")->required();
  app.add_option("--report", options->report, "Write a JSON report to this file");
  addKeepPartialFlag(app, options->keepPartial);
  return [options](const GlobalOptions& global) {
    const auto start = std::chrono::steady_clock::now();
    const PolygonMesh a = readMesh(options->first);
    const PolygonMesh b = readMesh(options->second);
    auto backend = makeBackend(global);
    projective::InterpolationSettings settings;
    settings.global.qp.onCheck = admmHeartbeat(global);
    projective::Interpolation interpolation(*backend, a, b, settings);
    projective::GlobalStepInfo info;
    const PolygonMesh result = interpolation.at(options->t, &info);
    const PlanarityStats stats = planarityStats(result);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nlohmann::json report = baseReport("interpolate", backend->name(), result, stats, seconds);
    report["t"] = options->t;
    report["iterations"] = info.admmIterations;  // ADMM iterations (0 when solved directly)
    report["epsilon_attempts"] = epsilonAttemptsJson(info.attempts);
    report["epsilon"] = info.epsilon;
    report["initial_violation"] = info.initialViolation;
    report["constraint_residual"] = info.constraintResidual;
    finishCommand("interpolate", CommandOutcome{projective::toString(info.status), ""}, options->keepPartial,
                  {{options->output, &result}}, report, options->report);
    std::ostringstream line;
    line << "interpolated at t = " << options->t << ", eps " << info.epsilon << ", max planarity " << stats.max
         << "% -> " << options->output;
    progress(global, line.str());
    return 0;
  };
}

const CommandRegistration registration{
    {"interpolate",
     "Interpolate or extrapolate between two polyhedral meshes (projective-maps paper, §7.1)", setup, 46}};

}  // namespace
}  // namespace plano::cli
