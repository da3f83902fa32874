// plano planarize MESH -o OUT [--tolerance PERCENT] [--closeness W] [--fixed FILE]
//   [--method gauss-newton|guided|anderson|shapeup] [--max-iterations N] [--report R.json]
//   [--keep-partial] [--in-place]
// Moves the vertices so that every face is planar within the tolerance (papers' measure,
// max over faces). Not reaching it within the cap exits with 4 and writes no mesh unless
// --keep-partial.
#include <chrono>
#include <filesystem>

#include "core/Error.h"
#include "mesh/Constraints.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "planarize/Planarize.h"
#include "plano/Command.h"
#include "plano/CommandOutcome.h"
#include "plano/Report.h"

namespace plano::cli {
namespace {

struct PlanarizeOptions {
  std::string input;
  std::string output;
  std::string fixed;
  std::string method = "gauss-newton";
  std::string report;
  double tolerance = planarize::Settings{}.tolerance;
  double closeness = planarize::Settings{}.closeness;
  int maxIterations = planarize::Settings{}.maxIterations;
  bool keepPartial = false;
  bool inPlace = false;
};

nlohmann::json reportJson(const PlanarizeOptions& options, const planarize::Settings& settings,
                          const planarize::Info& info, const PolygonMesh& result, const std::string& backend,
                          double seconds) {
  nlohmann::json j = baseReport("planarize", backend, result, planarityStats(result, settings.tolerance), seconds);
  j["input"] = options.input;
  j["method"] = planarize::toString(settings.method);
  j["status"] = planarize::toString(info.status);
  j["iterations"] = info.iterations;
  j["rejected_steps"] = info.rejectedSteps;
  j["corrector_steps"] = info.correctorSteps;
  j["closeness"] = settings.closeness;
  j["fixed_vertices"] = settings.fixed.size();
  j["planarity_per_iteration"] = {{"max", info.maxPlanarity}, {"mean", info.meanPlanarity}};
  j["displacement"] = {{"max", info.maxDisplacement}, {"mean", info.meanDisplacement}, {"unit", "bounding-box diagonal"}};
  j["linear_residual"] = info.linearResidual;
  j["solver_seconds"] = info.seconds;
  return j;
}

RunFunction setup(CLI::App& app) {
  auto options = std::make_shared<PlanarizeOptions>();
  app.add_option("mesh", options->input, "Input mesh (.obj, .off, .ply)")->required();
  app.add_option("-o,--output", options->output,
                 "Output mesh (.obj, .off, .ply); the input itself only with --in-place")
      ->required();
  app.add_option("--tolerance", options->tolerance, "Max face planarity to reach, percent")
      ->capture_default_str()
      ->check(nonNegativeNumber());
  app.add_option("--closeness", options->closeness,
                 "Weight of staying close to the input (larger: less displacement, slower or no convergence)")
      ->capture_default_str()
      ->check(nonNegativeNumber());
  app.add_option("--fixed", options->fixed, "Constraints JSON whose \"fixed\" vertices keep their positions");
  app.add_option("--method", options->method,
                 "gauss-newton (fastest), guided (plane unknowns), anderson (accelerated shapeup), shapeup (reference)")
      ->capture_default_str()
      ->check(CLI::IsMember({"gauss-newton", "guided", "anderson", "shapeup"}));
  app.add_option("--max-iterations", options->maxIterations, "Iteration cap")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000000));
  app.add_option("--report", options->report, "Write a JSON report to this file");
  addKeepPartialFlag(app, options->keepPartial);
  app.add_flag("--in-place", options->inPlace, "Allow the output to be the input file");
  return [options](const GlobalOptions& global) {
    const auto start = std::chrono::steady_clock::now();
    PolygonMesh mesh = readMesh(options->input);
    planarize::Settings settings;
    settings.method = planarize::parseMethod(options->method);
    settings.tolerance = options->tolerance;
    settings.closeness = options->closeness;
    settings.maxIterations = options->maxIterations;
    if (!options->fixed.empty()) {
      std::string warnings;
      const PositionalConstraints constraints = readConstraints(options->fixed, mesh.vertexCount(), &warnings);
      if (!warnings.empty()) progress(global, warnings);
      if (!constraints.handles.empty()) {
        throwUsage("planarize: constraints file '" + options->fixed +
                   "' has handles; planarize only keeps vertices fixed (use plano deform to move handles)");
      }
      settings.fixed = constraints.fixed;
    }
    auto backend = makeBackend(global);
    const planarize::Info info = planarize::planarize(mesh.faces, mesh.vertices, settings, *backend);
    const bool reached = info.status == planarize::Status::Converged;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    progress(global, "planarize (" + std::string(planarize::toString(settings.method)) + "): " +
                         std::string(planarize::toString(info.status)) + " after " + std::to_string(info.iterations) +
                         " iterations, max planarity " + std::to_string(info.maxPlanarity.front()) + "% -> " +
                         std::to_string(info.maxPlanarity.back()) + "%, max displacement " +
                         std::to_string(100.0 * info.maxDisplacement) + "% of the bounding-box diagonal");
    CommandOutcome outcome{planarize::toString(info.status), ""};
    if (!reached) {
      outcome.failure = "max planarity " + std::to_string(info.maxPlanarity.back()) + "% is above the tolerance " +
                        std::to_string(settings.tolerance) + "% after " + std::to_string(info.iterations) +
                        " iterations (" + planarize::toString(info.status) + ")";
    }
    finishCommand("planarize", outcome, options->keepPartial, {{options->output, &mesh}},
                  reportJson(*options, settings, info, mesh, backend->name(), seconds), options->report);
    return 0;
  };
}

const CommandRegistration registration{{"planarize", "Make every face planar within a tolerance", setup, 40}};

}  // namespace
}  // namespace plano::cli
