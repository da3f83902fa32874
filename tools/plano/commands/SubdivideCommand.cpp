// plano subdivide MESH (-o OUT | --in-place) --scheme catmull-clark|four-point --levels K
//   [--tolerance PERCENT] [--max-iterations N] [--linear] [--report R.json] [--keep-partial]
// Planar-quad subdivision (projective-maps paper, §5).
#include <algorithm>
#include <iomanip>
#include <sstream>

#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "plano/Command.h"
#include "plano/CommandOutcome.h"
#include "plano/Report.h"
#include "projective/PqSubdivision.h"

namespace plano::cli {
namespace {

struct SubdivideOptions {
  std::string input;
  std::string output;
  bool inPlace = false;
  std::string scheme = "catmull-clark";
  int levels = 1;
  double tolerance = -1.0;  ///< Percent; negative: the scheme's default (0.1 or 0.5).
  int maxIterations = 20;
  bool linear = false;
  std::string report;
  bool keepPartial = false;
};

nlohmann::json levelJson(const projective::PqLevelInfo& level) {
  nlohmann::json epsilons = nlohmann::json::array();
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& it : level.iterations) {
    epsilons.push_back(it.epsilon);
    nlohmann::json step = {{"epsilon", it.epsilon},
                           {"max_planarity", it.maxPlanarity},
                           {"max_change", it.maxChange},
                           {"constraint_residual", it.constraintResidual},
                           {"admm_iterations", it.admmIterations},
                           {"linear_iterations", it.linearIterations},
                           {"epsilon_attempts", epsilonAttemptsJson(it.attempts)}};
    addTransfers(step, it.transfers);
    steps.push_back(std::move(step));
  }
  return {{"level", level.level},
          {"vertices", level.vertices},
          {"faces", level.faces},
          {"converged", level.converged},
          {"iterations", level.iterations.size()},
          {"epsilons", epsilons},
          {"steps", steps},
          {"linear_max_planarity", level.linearMaxPlanarity},
          {"distance_to_linear", level.distanceToLinear},
          {"planarity", planarityJson(level.planarity)},
          {"seconds", level.seconds}};
}

RunFunction setup(CLI::App& app) {
  auto options = std::make_shared<SubdivideOptions>();
  app.add_option("mesh", options->input, "Mesh file (.obj, .off, .ply)")->required();
  auto* output = app.add_option("-o,--output", options->output, "Output mesh file (.obj, .off, .ply)");
  auto* inPlace = app.add_flag("--in-place", options->inPlace, "Overwrite the input mesh");
  output->excludes(inPlace);
  app.add_option("--scheme", options->scheme, "Linear scheme to imitate: catmull-clark | four-point")
      ->capture_default_str()
      ->check(CLI::IsMember({"catmull-clark", "four-point"}));
  app.add_option("--levels", options->levels, "Number of subdivision levels")
      ->capture_default_str()
      ->check(CLI::Range(0, 12));
  app.add_option("--tolerance", options->tolerance,
                 "Max planarity in percent (default 0.1 for catmull-clark, 0.5 for four-point); "
                 "the input's trivially refined faces must meet it")
      ->check(positiveNumber());
  app.add_option("--max-iterations", options->maxIterations, "Local/global iterations per level at most")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  app.add_flag("--linear", options->linear, "Only the linear scheme, without planarization");
  app.add_option("--report", options->report, "Write a JSON report to this file");
  addKeepPartialFlag(app, options->keepPartial);

  return [options](const GlobalOptions& global) {
    if (options->output.empty() && !options->inPlace) throwUsage("subdivide: give -o OUT or --in-place");
    const std::string target = options->inPlace ? options->input : options->output;
    const PolygonMesh input = readMesh(options->input);
    auto backend = makeBackend(global);

    projective::PqSubdivisionSettings settings;
    settings.scheme = projective::parseSubdivisionScheme(options->scheme);
    settings.levels = options->levels;
    settings.planarityTolerance =
        options->tolerance > 0.0 ? options->tolerance : (projective::isInterpolating(settings.scheme) ? 0.5 : 0.1);
    settings.maxIterationsPerLevel = options->maxIterations;
    settings.planarize = !options->linear;
    settings.globalStep.qp.onCheck = admmHeartbeat(global);
    // One line per local/global iteration: a level of a large mesh runs for minutes.
    const auto callback = [&](int level, int iteration, const projective::PqIteration& it) {
      std::ostringstream line;
      const auto skipped = std::count_if(it.attempts.begin(), it.attempts.end(), [](const auto& a) { return a.skipped; });
      const auto tried = static_cast<std::ptrdiff_t>(it.attempts.size()) - skipped;
      line << std::setprecision(3) << "level " << level << ", iteration " << iteration << ": max planarity "
           << it.maxPlanarity << "%, change " << it.maxChange << ", eps " << it.epsilon << ", ADMM "
           << it.admmIterations << " in " << tried << (tried == 1 ? " attempt" : " attempts");
      if (skipped > 0) line << " (" << skipped << " skipped: stalled before)";
      progress(global, line.str());
    };
    const projective::PqSubdivisionResult result =
        projective::subdividePlanarQuads(*backend, input, settings, callback);
    const projective::PqSubdivisionInfo& info = result.info;
    const PolygonMesh mesh = result.finestMesh();

    for (const auto& level : info.levels) {
      std::ostringstream line;
      line << std::setprecision(3) << "level " << level.level << ": " << level.faces << " faces, "
           << level.iterations.size() << " iterations, max planarity " << level.planarity.max << "% (linear scheme "
           << level.linearMaxPlanarity << "%)";
      progress(global, line.str());
    }
    const PlanarityStats stats = planarityStats(mesh, settings.planarityTolerance);
    nlohmann::json report = baseReport("subdivide", backend->name(), mesh, stats, info.seconds);
    report["scheme"] = options->scheme;
    report["iterations"] = info.totalIterations;
    nlohmann::json levels = nlohmann::json::array();
    for (const auto& level : info.levels) levels.push_back(levelJson(level));
    report["levels"] = levels;
    CommandOutcome outcome{projective::toString(info.status), ""};
    if (info.status == projective::PqSubdivisionStatus::IterationLimit) {
      std::ostringstream failure;
      failure << "some level did not reach " << settings.planarityTolerance << "% max planarity in "
              << settings.maxIterationsPerLevel << " iterations";
      outcome.failure = failure.str();
    }
    finishCommand("subdivide", outcome, options->keepPartial, {{target, &mesh}}, report, options->report);
    return 0;
  };
}

const CommandRegistration registration{
    {"subdivide", "Planar-quad subdivision imitating Catmull-Clark or the four-point scheme", setup, 40}};

}  // namespace
}  // namespace plano::cli
