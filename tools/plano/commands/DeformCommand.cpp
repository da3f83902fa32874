// plano deform MESH --constraints C.json -o OUT: as-rigid/as-similar-as-possible editing of a
// polyhedral mesh in the projective shape space (projective-maps paper, §6.1).
//
// The command is split into option parsing, one function per deformation method (today:
// the single-level projective deformation) and the common output/report handling, so that
// another method is one more function and one more branch in `runMethod`.
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "core/Error.h"
#include "mesh/Constraints.h"
#include "mesh/MeshIO.h"
#include "plano/Command.h"
#include "plano/Report.h"
#include "projective/Deformation.h"

namespace plano::cli {
namespace {

struct DeformOptions {
  std::string input;
  std::string constraints;
  std::string output;
  std::string energy = "rigid";
  double smoothness = 0.0;
  int maxIterations = 100;
  double tolerance = 1e-4;
  double planarityTolerance = 0.1;
  std::string report;
  bool keepPartial = false;
  bool inPlace = false;
};

/// What a deformation method hands back to the common output code.
struct DeformOutcome {
  PolygonMesh mesh;
  bool succeeded = false;
  std::string message;        ///< Why it did not succeed.
  int iterations = 0;
  nlohmann::json details;     ///< Method-specific report keys.
};

nlohmann::json iterationJson(const projective::DeformationIteration& it) {
  nlohmann::json attempts = nlohmann::json::array();
  for (const auto& a : it.attempts) {
    attempts.push_back({{"epsilon", a.epsilon}, {"status", projective::toString(a.status)}, {"iterations", a.iterations}});
  }
  return {{"iteration", it.iteration},
          {"phase", it.phase == projective::DeformationPhase::Ideal ? "ideal" : "projection"},
          {"epsilon", it.epsilon},
          {"initial_violation", it.initialViolation},
          {"constraint_residual", it.constraintResidual},
          {"positional_residual", it.positionalResidual},
          {"admm_iterations", it.admmIterations},
          {"displacement", it.displacement},
          {"max_planarity", it.maxPlanarity},
          {"epsilon_attempts", attempts}};
}

DeformOutcome runSingleLevel(const DeformOptions& options, const GlobalOptions& global, compute::Backend& backend,
                             const PolygonMesh& mesh, const PositionalConstraints& constraints) {
  projective::DeformationSettings settings;
  settings.energy = options.energy == "similar" ? projective::IdealMapKind::Similar : projective::IdealMapKind::Rigid;
  settings.global.smoothness = options.smoothness;
  settings.maxIterations = options.maxIterations;
  settings.tolerance = options.tolerance;
  settings.planarityTolerance = options.planarityTolerance;

  const auto callback = [&](const projective::DeformationIteration& it) {
    std::ostringstream line;
    line << std::setprecision(3) << "iteration " << it.iteration
         << (it.phase == projective::DeformationPhase::Ideal ? "" : " (projection)") << ": displacement "
         << it.displacement << ", eps " << it.epsilon << ", constraint residual " << it.constraintResidual
         << ", ADMM " << it.admmIterations << ", max planarity " << it.maxPlanarity << "%";
    progress(global, line.str());
  };
  const projective::DeformationResult result = projective::deform(backend, mesh, constraints, settings, callback);

  DeformOutcome outcome;
  outcome.mesh = result.mesh;
  outcome.iterations = result.info.iterations;
  outcome.succeeded = result.info.status == projective::DeformationStatus::Converged;
  outcome.message = result.info.status == projective::DeformationStatus::NumericalFailure
                        ? result.info.message
                        : "not converged after " + std::to_string(result.info.iterations) +
                              " iterations (max planarity " + std::to_string(result.info.planarity.max) + "%)";
  nlohmann::json epsilons = nlohmann::json::array();
  nlohmann::json residuals = nlohmann::json::array();
  nlohmann::json history = nlohmann::json::array();
  for (const auto& it : result.info.history) {
    epsilons.push_back(it.epsilon);
    residuals.push_back(it.constraintResidual);
    history.push_back(iterationJson(it));
  }
  outcome.details = {{"method", "single-level"},
                     {"energy", options.energy},
                     {"smoothness", options.smoothness},
                     {"tolerance", options.tolerance},
                     {"status", projective::toString(result.info.status)},
                     {"epsilon", epsilons},
                     {"residuals", residuals},
                     {"max_constraint_error", result.info.maxConstraintError},
                     {"history", history}};
  if (!result.info.message.empty()) outcome.details["message"] = result.info.message;
  return outcome;
}

/// The one place where a deformation method is chosen.
DeformOutcome runMethod(const DeformOptions& options, const GlobalOptions& global, compute::Backend& backend,
                        const PolygonMesh& mesh, const PositionalConstraints& constraints) {
  return runSingleLevel(options, global, backend, mesh, constraints);
}

bool samePath(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (std::filesystem::exists(a) && std::filesystem::exists(b)) return std::filesystem::equivalent(a, b, ec);
  return std::filesystem::weakly_canonical(a, ec) == std::filesystem::weakly_canonical(b, ec);
}

RunFunction setup(CLI::App& app) {
  auto options = std::make_shared<DeformOptions>();
  app.add_option("mesh", options->input, "Polyhedral mesh to deform (.obj, .off, .ply)")->required();
  app.add_option("--constraints", options->constraints,
                 "JSON file {\"fixed\": [i, ...], \"handles\": [{\"vertex\": i, \"position\": [x, y, z]}]}")
      ->required();
  app.add_option("-o,--output", options->output, "Output mesh file")->required();
  app.add_option("--energy", options->energy, "Ideal maps of the local step")
      ->check(CLI::IsMember({"rigid", "similar"}))
      ->capture_default_str();
  app.add_option("--smoothness", options->smoothness, "alpha of the map-smoothness term (paper §6.3)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--max-iterations", options->maxIterations, "Local/global iterations of the rigid/similar phase")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--tolerance", options->tolerance,
                 "Stop when the max vertex displacement per iteration is below this fraction of the bounding-box "
                 "diagonal")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--planarity-tolerance", options->planarityTolerance,
                 "Max face planarity (percent) the result must reach")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--report", options->report, "Write a JSON report to this file");
  app.add_flag("--keep-partial", options->keepPartial, "Write the last iterate even when the deformation fails");
  app.add_flag("--in-place", options->inPlace, "Allow the output to overwrite the input mesh");
  return [options](const GlobalOptions& global) {
    const auto start = std::chrono::steady_clock::now();
    if (!options->inPlace && samePath(options->input, options->output)) {
      throwUsage("output " + options->output + " is the input mesh; pass --in-place to overwrite it");
    }
    const PolygonMesh mesh = readMesh(options->input);
    std::string warnings;
    const PositionalConstraints constraints = readConstraints(options->constraints, mesh.vertexCount(), &warnings);
    if (!warnings.empty()) std::cerr << warnings;
    if (constraints.handles.empty()) progress(global, "warning: no handles: the mesh will not move");
    auto backend = makeBackend(global);

    const DeformOutcome outcome = runMethod(*options, global, *backend, mesh, constraints);
    const PlanarityStats stats = planarityStats(outcome.mesh);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nlohmann::json report = baseReport("deform", backend->name(), outcome.mesh, stats, seconds);
    report["iterations"] = outcome.iterations;
    report.update(outcome.details);
    const bool write = outcome.succeeded || options->keepPartial;
    report["output_written"] = write;
    if (write) writeMesh(options->output, outcome.mesh);
    writeReport(options->report, report);
    if (!outcome.succeeded) {
      throwNumerical("deform: " + outcome.message +
                     (options->keepPartial ? "; partial result written to " + options->output
                                           : "; no output written (use --keep-partial to write the last iterate)"));
    }
    progress(global, "deformed in " + std::to_string(outcome.iterations) + " iterations, max planarity " +
                         std::to_string(stats.max) + "% -> " + options->output);
    return 0;
  };
}

const CommandRegistration registration{
    {"deform", "As-rigid/as-similar-as-possible editing in the projective shape space", setup, 40}};

}  // namespace
}  // namespace plano::cli
