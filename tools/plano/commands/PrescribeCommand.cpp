// plano prescribe MESH --map rotate|warp|scale -o OUT: editing by direct map prescription
// (projective-maps paper, §7): prescribe one kind of map to all or selected faces, keep the
// constrained vertices, project onto the polyhedral shape space.
#include <chrono>
#include <numbers>
#include <sstream>

#include "core/Error.h"
#include "mesh/Constraints.h"
#include "mesh/MeshIO.h"
#include "plano/Command.h"
#include "plano/CommandOutcome.h"
#include "plano/Report.h"
#include "projective/MapPrescription.h"
#include "projective/UniformScaling.h"

namespace plano::cli {
namespace {

struct PrescribeOptions {
  std::string input;
  std::string output;
  std::string map;
  std::vector<double> axis = {0.0, 0.0, 1.0};
  double angle = 0.0;
  double strength = 0.0;
  double scale = 1.0;
  std::string pivot = "centre";
  std::vector<double> point = {0.0, 0.0, 0.0};
  std::vector<Index> faces;
  std::string constraints;
  std::string report;
  bool inPlace = false;
  bool keepPartial = false;
};

nlohmann::json stepJson(const projective::GlobalStepInfo& info) {
  return {{"status", projective::toString(info.status)},
          {"epsilon", info.epsilon},
          {"initial_violation", info.initialViolation},
          {"constraint_residual", info.constraintResidual},
          {"positional_residual", info.positionalResidual},
          {"admm_iterations", info.admmIterations},
          {"linear_iterations", info.linearIterations},
          {"epsilon_attempts", epsilonAttemptsJson(info.attempts)}};
}

RunFunction setup(CLI::App& app) {
  auto options = std::make_shared<PrescribeOptions>();
  app.add_option("mesh", options->input, "Polyhedral mesh (.obj, .off, .ply)")->required();
  app.add_option("-o,--output", options->output, "Output mesh file")->required();
  app.add_option("--map", options->map, "Prescribed map: rotate, warp (boxes to frusta) or scale (diag(t,t,t,1))")
      ->required()
      ->check(CLI::IsMember({"rotate", "warp", "scale"}));
  app.add_option("--axis", options->axis, "Rotation axis or warp direction (3 numbers)")->expected(3)->capture_default_str();
  app.add_option("--angle", options->angle, "Rotation angle in degrees")->capture_default_str();
  app.add_option("--strength", options->strength,
                 "Warp: change of the homogeneous weight per bounding-box diagonal along the axis (|k| < 2)")
      ->check(numberBetween(-2.0, 2.0, /*open=*/true))
      ->capture_default_str();
  app.add_option("--t", options->scale, "Scaling factor t (0: as-minimal-as-possible)")->capture_default_str();
  app.add_option("--pivot", options->pivot, "Centre of the maps: centre (of the mesh), face (each face's centroid), point")
      ->check(CLI::IsMember({"centre", "face", "point"}))
      ->capture_default_str();
  const CLI::Option* point =
      app.add_option("--point", options->point, "Pivot point for --pivot point (3 numbers)")->expected(3);
  app.add_option("--faces", options->faces, "Faces that get the map (0-based; default all), others get the identity")
      ->delimiter(',');
  app.add_option("--constraints", options->constraints, "JSON constraints file: fixed vertices and handles");
  app.add_option("--report", options->report, "Write a JSON report to this file");
  app.add_flag("--in-place", options->inPlace, "Allow the output to overwrite the input mesh");
  addKeepPartialFlag(app, options->keepPartial);
  return [options, point](const GlobalOptions& global) {
    // Otherwise silently ignored: the maps would turn about another centre than the one given.
    if (point->count() > 0 && options->pivot != "point") {
      throwUsage("prescribe: --point is the centre of --pivot point (got --pivot " + options->pivot + ")");
    }
    const auto start = std::chrono::steady_clock::now();
    const PolygonMesh mesh = readMesh(options->input);
    PositionalConstraints constraints;
    if (!options->constraints.empty()) {
      std::string warnings;
      constraints = readConstraints(options->constraints, mesh.vertexCount(), &warnings);
      if (!warnings.empty()) std::cerr << warnings;
    }
    for (Index f : options->faces) {
      if (f < 0 || f >= mesh.faceCount()) {
        throwUsage("--faces: face " + std::to_string(f) + " is out of range (" + std::to_string(mesh.faceCount()) +
                   " faces)");
      }
    }
    auto backend = makeBackend(global);
    const projective::Pivot pivot = options->pivot == "face"    ? projective::Pivot::FaceCentroid
                                    : options->pivot == "point" ? projective::Pivot::Point
                                                                : projective::Pivot::MeshCentre;
    PolygonMesh result;
    nlohmann::json steps = nlohmann::json::array();
    if (options->map == "scale") {
      // §7: two solves (t = 0 and t = 1) span the line of compatible scalings.
      const projective::UniformScalingFamily family(*backend, mesh, pivot, options->faces, constraints);
      result = family.mesh(options->scale);
      steps.push_back(stepJson(family.firstSolve()));
      steps.push_back(stepJson(family.secondSolve()));
    } else {
      projective::MapPrescription prescription;
      prescription.kind = options->map == "rotate" ? projective::PrescribedMapKind::Rotation
                                                   : projective::PrescribedMapKind::PerspectiveWarp;
      prescription.axis = Eigen::Vector3d(options->axis[0], options->axis[1], options->axis[2]);
      prescription.angle = options->angle * std::numbers::pi / 180.0;
      prescription.strength = options->strength;
      prescription.pivot = pivot;
      prescription.point = Eigen::Vector3d(options->point[0], options->point[1], options->point[2]);
      projective::PrescriptionSettings settings;
      settings.global.qp.onCheck = admmHeartbeat(global);
      const projective::PrescriptionResult r =
          projective::prescribeMaps(*backend, mesh, prescription, options->faces, constraints, settings);
      result = r.mesh;
      steps.push_back(stepJson(r.info));
      for (const auto& step : r.projection) steps.push_back(stepJson(step));
    }
    const PlanarityStats stats = planarityStats(result);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nlohmann::json report = baseReport("prescribe", backend->name(), result, stats, seconds);
    report["map"] = options->map;
    report["pivot"] = options->pivot;
    report["iterations"] = steps.size();
    report["global_steps"] = steps;
    nlohmann::json epsilons = nlohmann::json::array();
    for (const auto& s : steps) epsilons.push_back(s["epsilon"]);
    report["epsilon"] = epsilons;
    // Failures of the global steps (no feasible eps within the schedule) throw Error(Numerical).
    finishCommand("prescribe", CommandOutcome{"solved", ""}, options->keepPartial, {{options->output, &result}}, report,
                  options->report);
    std::ostringstream line;
    line << "prescribed " << options->map << " on " << (options->faces.empty() ? mesh.faceCount() : options->faces.size())
         << " faces, " << steps.size() << " global steps, max planarity " << stats.max << "% -> " << options->output;
    progress(global, line.str());
    return 0;
  };
}

const CommandRegistration registration{
    {"prescribe",
     "Prescribe rotations, perspective warps or scalings to faces (projective-maps paper, §7)", setup, 45}};

}  // namespace
}  // namespace plano::cli
