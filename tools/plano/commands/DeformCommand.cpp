// plano deform MESH --constraints C.json -o OUT: as-rigid/as-similar-as-possible editing of a
// polyhedral mesh in the projective shape space (projective-maps paper, §6.1).
//
// The command is split into option parsing, one function per deformation method (today:
// the single-level projective deformation) and the common output/report handling, so that
// another method is one more function and one more branch in `runMethod`.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "core/Error.h"
#include "mesh/Constraints.h"
#include "mesh/MeshIO.h"
#include "plano/Command.h"
#include "plano/CommandOutcome.h"
#include "plano/LinearSpaceOptions.h"
#include "plano/Report.h"
#include "plano/commands/SubspaceDeform.h"
#include "projective/Deformation.h"
#include "projective/MultiresDeformation.h"
#include "projective/PqSubdivision.h"

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
  // --multires (paper §6): MESH is the subdivision of --base by `plano subdivide`.
  bool multires = false;
  std::string base;
  std::string scheme = "catmull-clark";
  int multiresLevel = -1;
  // --space (linear-spaces paper §3): deformation inside a linear space of polyhedral meshes.
  LinearSpaceOptions linearSpace{""};  ///< --space not given: the projective shape space.
  const CLI::Option* smoothnessOption = nullptr;  ///< Tells whether --smoothness was given.
  const CLI::Option* toleranceOption = nullptr;   ///< Tells whether --tolerance was given.
  const CLI::Option* maxIterationsOption = nullptr;
  const CLI::Option* upOption = nullptr;  ///< Tells whether --up was given.
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
  nlohmann::json entry = {{"iteration", it.iteration},
          {"phase", it.phase == projective::DeformationPhase::Ideal ? "ideal" : "projection"},
          {"epsilon", it.epsilon},
          {"initial_violation", it.initialViolation},
          {"constraint_residual", it.constraintResidual},
          {"positional_residual", it.positionalResidual},
          {"admm_iterations", it.admmIterations},
          {"linear_iterations", it.linearIterations},
          {"polish_refinements", it.polishRefinements},
          {"displacement", it.displacement},
          {"max_planarity", it.maxPlanarity},
          {"epsilon_attempts", epsilonAttemptsJson(it.attempts)}};
  addTransfers(entry, it.transfers);
  return entry;
}

/// Which stopping bound the last rigid/similar iteration missed, with its tolerance.
std::string notConvergedReason(const projective::DeformationInfo& info,
                               const projective::DeformationSettings& settings) {
  double displacement = 0.0;
  double projectionDisplacement = -1.0;  // largest move of a projection iteration; < 0: none ran
  for (const auto& it : info.history) {
    if (it.phase == projective::DeformationPhase::Ideal) {
      displacement = it.displacement;
    } else {
      projectionDisplacement = std::max(projectionDisplacement, it.displacement);
    }
  }
  std::ostringstream reason;
  reason << std::setprecision(3) << "not converged after " << info.iterations
         << " iterations: the last rigid/similar one moved a vertex by " << displacement
         << " of the diagonal (tolerance " << settings.tolerance << "), max planarity " << info.planarity.max
         << "% (tolerance " << settings.planarityTolerance << "%)";
  if (projectionDisplacement >= 0.0) {
    reason << "; the projection to planar faces then moved a vertex by " << projectionDisplacement
           << " of the diagonal";
    // Planar faces that meet the constraints exist only far from the rigid/similar shape:
    // a mesh whose faces the projection has to move by more than the whole bounding box.
    if (projectionDisplacement > 1.0) {
      reason << " (the constraints admit planar meshes only far from the rigid/similar shape: handles that "
                "pull against each other?)";
    }
  }
  return reason.str();
}

DeformOutcome runSingleLevel(const DeformOptions& options, const GlobalOptions& global, compute::Backend& backend,
                             const PolygonMesh& mesh, const PositionalConstraints& constraints) {
  projective::DeformationSettings settings;
  settings.energy = options.energy == "similar" ? projective::IdealMapKind::Similar : projective::IdealMapKind::Rigid;
  settings.global.smoothness = options.smoothness;
  settings.maxIterations = options.maxIterations;
  settings.tolerance = options.tolerance;
  settings.planarityTolerance = options.planarityTolerance;
  settings.global.qp.onCheck = admmHeartbeat(global);

  const auto callback = [&](const projective::DeformationIteration& it) {
    std::ostringstream line;
    line << std::setprecision(3) << "iteration " << it.iteration
         << (it.phase == projective::DeformationPhase::Ideal ? "" : " (projection)") << ": displacement "
         << it.displacement << ", eps " << it.epsilon << ", constraint residual " << it.constraintResidual;
    // An exact step that the backend solved without ADMM (projective/BoxQp.h) says so.
    if (!it.attempts.empty() && it.attempts.back().direct) {
      line << ", solved directly";
    } else {
      line << ", ADMM " << it.admmIterations;
    }
    line << ", max planarity " << it.maxPlanarity << "%";
    progress(global, line.str());
  };
  const projective::DeformationResult result = projective::deform(backend, mesh, constraints, settings, callback);

  DeformOutcome outcome;
  outcome.mesh = result.mesh;
  outcome.iterations = result.info.iterations;
  outcome.succeeded = result.info.status == projective::DeformationStatus::Converged;
  outcome.message = result.info.status == projective::DeformationStatus::NumericalFailure
                        ? result.info.message
                        : notConvergedReason(result.info, settings);
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

// ---- multi-resolution editing (paper §6) -----------------------------------------

/// Rebuild the subdivision hierarchy of `base` whose finest level is `mesh`: the number of
/// levels follows from the face counts, the topology must match face by face, and the
/// user's fine positions replace the recomputed ones (the coarse levels come from the
/// recomputation).
projective::PqSubdivisionResult rebuildHierarchy(const DeformOptions& options, const GlobalOptions& global,
                                                 compute::Backend& backend, const PolygonMesh& mesh) {
  const PolygonMesh base = readMesh(options.base);
  // Level 1 has one quad per base corner, every further level four times as many.
  int levels = 0;
  for (Index faces = base.faceCount(); faces < mesh.faceCount() && levels < 12; ++levels) {
    faces = levels == 0 ? base.faces.cornerCount() : 4 * faces;
  }
  projective::PqSubdivisionSettings settings;
  settings.scheme = projective::parseSubdivisionScheme(options.scheme);
  settings.levels = levels;
  settings.planarityTolerance = projective::isInterpolating(settings.scheme) ? 0.5 : 0.1;
  settings.globalStep.qp.onCheck = admmHeartbeat(global);
  const auto hierarchyOnly = projective::SubdivisionHierarchy(base.faces, base.vertexCount(), levels);
  if (levels == 0 || !(hierarchyOnly.faces(levels) == mesh.faces)) {
    throwBadInput(options.input + " is not a subdivision of " + options.base + " (" +
                  std::to_string(mesh.faceCount()) + " faces; no level of the hierarchy of the base has the same faces)");
  }
  progress(global, "multires: rebuilding " + std::to_string(levels) + " " + options.scheme + " levels of " + options.base);
  projective::PqSubdivisionResult subdivision = projective::subdividePlanarQuads(backend, base, settings);
  const double offset = (subdivision.positions.back() - mesh.vertices).rowwise().norm().maxCoeff();
  if (offset > 1e-6 * boundingBoxDiagonal(mesh.vertices)) {
    progress(global, "warning: " + options.input + " differs from the subdivision of " + options.base + " by up to " +
                         std::to_string(offset) + "; its positions are used on the finest level");
  }
  subdivision.positions.back() = mesh.vertices;
  return subdivision;
}

DeformOutcome runMultires(const DeformOptions& options, const GlobalOptions& global, compute::Backend& backend,
                          const PolygonMesh& mesh, const PositionalConstraints& constraints) {
  if (options.base.empty()) throwUsage("deform --multires needs --base BASE, the mesh that MESH was subdivided from");
  const auto start = std::chrono::steady_clock::now();
  const projective::PqSubdivisionResult subdivision = rebuildHierarchy(options, global, backend, mesh);
  const double hierarchySeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  projective::MultiresSettings settings;
  settings.energy = options.energy == "similar" ? projective::IdealMapKind::Similar : projective::IdealMapKind::Rigid;
  if (options.smoothnessOption != nullptr && options.smoothnessOption->count() > 0) settings.smoothness = options.smoothness;
  settings.level = options.multiresLevel;
  settings.maxCoarseIterations = options.maxIterations;
  settings.tolerance = options.tolerance;
  settings.planarityTolerance = options.planarityTolerance;
  settings.global.qp.onCheck = admmHeartbeat(global);
  const auto callback = [&](const projective::MultiresIteration& it) {
    std::ostringstream line;
    line << std::setprecision(3) << "multires ";
    if (it.phase == projective::MultiresPhase::Coarse) {
      line << "iteration " << it.iteration << ": displacement " << it.displacement << ", eps " << it.epsilon;
    } else {
      line << "projection " << it.iteration << " of the fine mesh";
    }
    line << ", max planarity " << it.maxPlanarity << "%";
    progress(global, line.str());
  };
  const projective::MultiresResult result = projective::multiresDeform(backend, subdivision.hierarchy,
                                                                       subdivision.positions, constraints, settings, callback);
  const projective::MultiresInfo& info = result.info;
  progress(global, "multires: deformed on level " + std::to_string(info.level) + " (" +
                       std::to_string(info.coarseFaces) + " faces) in " + std::to_string(info.coarseIterations) +
                       " iterations, prolonged to " + std::to_string(info.fineFaces) + " faces");

  DeformOutcome outcome;
  outcome.mesh = PolygonMesh{result.positions, mesh.faces};
  outcome.iterations = info.coarseIterations + info.projectionIterations;
  outcome.succeeded = info.status == projective::MultiresStatus::Converged;
  outcome.message = "multires: not converged (max planarity " + std::to_string(info.planarity.max) + "%)";
  nlohmann::json checks = nlohmann::json::array();
  for (const auto& check : info.levelChecks) {
    checks.push_back({{"level", check.level}, {"admissible", check.admissible}, {"reason", check.reason}});
  }
  outcome.details = {{"method", "multires"},
                     {"energy", options.energy},
                     {"scheme", options.scheme},
                     {"smoothness", settings.smoothness},
                     {"status", projective::toString(info.status)},
                     {"level", info.level},
                     {"levels", subdivision.hierarchy.finestLevel()},
                     {"level_checks", checks},
                     {"coarse_faces", info.coarseFaces},
                     {"fine_faces", info.fineFaces},
                     {"coarse_iterations", info.coarseIterations},
                     {"epsilon", info.coarseEpsilons},
                     {"displacements", info.coarseDisplacements},
                     {"fine_epsilon", info.fineStep.epsilon},
                     {"fine_epsilon_attempts", epsilonAttemptsJson(info.fineStep.attempts)},
                     {"projection_iterations", info.projectionIterations},
                     {"max_handle_error", info.maxHandleError},
                     {"max_fixed_error", info.maxFixedError},
                     {"times", {{"hierarchy", hierarchySeconds},
                                {"coarse_deform", info.coarseSeconds},
                                {"prolongation", info.prolongationSeconds},
                                {"deform", info.seconds}}}};
  addTransferList(outcome.details, "coarse_device_transfers", info.coarseTransfers);
  addTransferList(outcome.details, "projection_device_transfers", info.projectionTransfers);
  return outcome;
}

/// The one place where a deformation method is chosen.
DeformOutcome runMethod(const DeformOptions& options, const GlobalOptions& global, compute::Backend& backend,
                        const PolygonMesh& mesh, const PositionalConstraints& constraints) {
  if (options.multires) return runMultires(options, global, backend, mesh, constraints);
  return runSingleLevel(options, global, backend, mesh, constraints);
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
      ->check(nonNegativeNumber())
      ->capture_default_str();
  app.add_option("--max-iterations", options->maxIterations, "Local/global iterations of the rigid/similar phase")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--tolerance", options->tolerance,
                 "Stop when the max vertex displacement per iteration is below this fraction of the bounding-box "
                 "diagonal")
      ->check(positiveNumber())
      ->capture_default_str();
  app.add_option("--planarity-tolerance", options->planarityTolerance,
                 "Max face planarity (percent) the result must reach")
      ->check(positiveNumber())
      ->capture_default_str();
  app.add_option("--report", options->report, "Write a JSON report to this file");
  addKeepPartialFlag(app, options->keepPartial);
  app.add_flag("--in-place", options->inPlace, "Allow the output to overwrite the input mesh");
  // Multi-resolution editing (paper §6).
  CLI::Option* multires = app.add_flag("--multires", options->multires,
               "Multi-resolution editing: deform on the coarsest admissible level of the subdivision hierarchy of "
               "--base and prolong (smoothness defaults to 3.5)");
  // Without --multires these would be ignored silently.
  app.add_option("--base", options->base, "With --multires: the coarse mesh that MESH was subdivided from")
      ->needs(multires);
  app.add_option("--scheme", options->scheme, "With --multires: the scheme MESH was subdivided with")
      ->check(CLI::IsMember({"catmull-clark", "four-point"}))
      ->capture_default_str()
      ->needs(multires);
  app.add_option("--multires-level", options->multiresLevel,
                 "With --multires: deform on this level instead of the automatic choice")
      ->needs(multires);
  // Deformation inside a linear space (linear-spaces paper §3, Fig. 8).
  addLinearSpaceOptions(app, options->linearSpace,
                        "Deform inside a linear space of polyhedral meshes instead of the projective shape space "
                        "(ASAP for --energy similar, ARAP for rigid): affine | parallel | vertical | mixed");
  options->smoothnessOption = app.get_option("--smoothness");
  options->toleranceOption = app.get_option("--tolerance");
  options->maxIterationsOption = app.get_option("--max-iterations");
  options->upOption = app.get_option("--up");
  return [options](const GlobalOptions& global) {
    if (options->linearSpace.space.empty() &&
        (options->upOption->count() > 0 || !options->linearSpace.facesFile.empty())) {
      throwUsage("deform: --up and --faces-file choose a linear space and need --space");
    }
    if (!options->linearSpace.space.empty()) {
      if (options->multires) throwUsage("deform: --space and --multires cannot be combined");
      SubspaceDeformRequest request;
      request.mesh = options->input;
      request.constraints = options->constraints;
      request.linearSpace = options->linearSpace;
      request.energy = options->energy == "similar" ? "asap" : "arap";
      request.output = options->output;
      request.report = options->report;
      request.keepPartial = options->keepPartial;
      if (options->maxIterationsOption->count() > 0) request.maxIterations = options->maxIterations;
      if (options->toleranceOption->count() > 0) request.tolerance = options->tolerance;
      return runSubspaceDeform(request, global);
    }
    const auto start = std::chrono::steady_clock::now();
    const PolygonMesh mesh = readMesh(options->input);
    std::string warnings;
    const PositionalConstraints constraints = readConstraints(options->constraints, mesh.vertexCount(), &warnings);
    if (!warnings.empty()) std::cerr << warnings;
    // As `deform --space`: a file without any constraint is most likely the wrong file.
    if (constraints.empty()) throwBadInput(options->constraints + ": no fixed vertex and no handle");
    if (constraints.handles.empty()) std::cerr << "warning: no handles: the mesh will not move" << std::endl;
    auto backend = makeBackend(global);

    const DeformOutcome outcome = runMethod(*options, global, *backend, mesh, constraints);
    const PlanarityStats stats = planarityStats(outcome.mesh);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nlohmann::json report = baseReport("deform", backend->name(), outcome.mesh, stats, seconds);
    report["iterations"] = outcome.iterations;
    report.update(outcome.details);
    CommandOutcome result{report["status"].get<std::string>(), outcome.succeeded ? "" : outcome.message};
    finishCommand("deform", result, options->keepPartial, {{options->output, &outcome.mesh}}, report, options->report);
    progress(global, "deformed in " + std::to_string(outcome.iterations) + " iterations, max planarity " +
                         std::to_string(stats.max) + "% -> " + options->output);
    return 0;
  };
}

const CommandRegistration registration{
    {"deform", "As-rigid/as-similar-as-possible editing in the projective shape space", setup, 40}};

}  // namespace
}  // namespace plano::cli
