// plano dual MESH -o OUT [--space S --eigenshape K --amplitude A --primal P]: the polar dual
// of a polyhedral mesh, and optionally an exploration of the dual's linear space whose
// primal mesh (recovered by a linear solve) is written to P (linear-spaces paper, §3, Fig. 9).
#include <chrono>
#include <iostream>

#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "plano/Command.h"
#include "plano/CommandOutcome.h"
#include "plano/LinearSpaceOptions.h"
#include "plano/Report.h"
#include "subspace/Eigenshapes.h"
#include "subspace/LinearSpace.h"
#include "subspace/MeshLaplacian.h"
#include "subspace/PolarDual.h"

namespace plano::cli {
namespace {

using namespace plano::subspace;

struct DualOptions {
  std::string input, output, report, primal;
  LinearSpaceOptions linearSpace{"parallel"};  ///< Of the dual; not mixed.
  Index eigenshape = 3;
  double amplitude = 0.05;
  bool keepPartial = false;
};

RunFunction setup(CLI::App& app) {
  auto o = std::make_shared<DualOptions>();
  app.add_option("mesh", o->input, "Polyhedral mesh (no face plane through the origin)")->required();
  app.add_option("-o,--output", o->output, "Output dual mesh")->required();
  app.add_option("--primal", o->primal, "Explore the dual: write the primal of the edited dual here");
  app.add_option("--space", o->linearSpace.space, "Linear space of the dual to explore: affine | parallel | vertical")
      ->check(CLI::IsMember({"affine", "parallel", "vertical"}))
      ->capture_default_str();
  addUpOption(app, o->linearSpace.up);
  app.add_option("--eigenshape", o->eigenshape, "Which eigenshape of the dual's space to add (0 = lowest)")
      ->capture_default_str();
  app.add_option("--amplitude", o->amplitude, "Peak displacement of the dual, relative to its bounding-box diagonal")
      ->check(numberBetween(-kMaxAmplitude, kMaxAmplitude))
      ->capture_default_str();
  app.add_option("--report", o->report, "Write a JSON report to this file");
  addKeepPartialFlag(app, o->keepPartial);
  return [o](const GlobalOptions& global) {
    // The dual alone is geometry on the CPU; exploring it forms a reduced operator on the backend.
    std::unique_ptr<compute::Backend> backend;
    const std::string backendName =
        o->primal.empty()
            ? warnComputesOnCpu(global, "dual", "the polar dual alone is a per-face construction without a solve")
            : (backend = makeLinearSpaceBackend(global, "dual", "the reduced operator runs"))->name();
    const auto start = std::chrono::steady_clock::now();
    const PolygonMesh mesh = readMesh(o->input);
    const PolygonMesh dual = polarDual(mesh);
    nlohmann::json j;
    PlanarityStats stats = planarityStats(dual);
    nlohmann::json exploration;
    PolygonMesh primal = mesh;
    if (!o->primal.empty()) {
      const LinearSpace space =
          buildSpaceWithProgress(global, "dual", dual, "dual's " + o->linearSpace.space,
                                 o->linearSpace.assignment(dual.faceCount()), o->linearSpace.settings());
      EigenshapeSettings es;
      es.count = o->eigenshape + 1;
      const Eigenshapes shapes = computeEigenshapes(*backend, space.N, uniformLaplacian(dual.faces, dual.vertexCount()), es);
      if (o->eigenshape >= shapes.count()) {
        throwUsage("--eigenshape " + std::to_string(o->eigenshape) + " but the dual's " + o->linearSpace.space +
                   " space has dimension " + std::to_string(space.N.dimension()));
      }
      const Positions edited = bandPass(space.N, shapes, space.N.project(dual.vertices), o->eigenshape,
                                        o->eigenshape + 1, o->amplitude);
      primal.vertices = primalFromDual(mesh.faces, edited, mesh.vertices);
      stats = planarityStats(primal);
      exploration = {{"space", o->linearSpace.space},
                     {"dimension", space.dof.dimension},
                     {"eigenshape", o->eigenshape},
                     {"frequency", shapes.frequencies[o->eigenshape]},
                     {"primal", o->primal},
                     {"primal_max_planarity", stats.max}};
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    j = baseReport("dual", backendName, o->primal.empty() ? dual : mesh, stats, seconds);
    j["dual_vertices"] = dual.vertexCount();
    j["dual_faces"] = dual.faceCount();
    j["dual_max_planarity"] = planarityStats(dual).max;
    if (!exploration.is_null()) j["exploration"] = exploration;
    std::vector<MeshOutput> outputs{{o->output, &dual}};
    if (!o->primal.empty()) outputs.push_back({o->primal, &primal});
    finishCommand("dual", CommandOutcome{}, o->keepPartial, outputs, j, o->report);
    // Only now: the files named here are written.
    if (!exploration.is_null()) {
      std::cout << "explored the dual's " << o->linearSpace.space << " space (dimension " << exploration["dimension"]
                << "), primal max planarity " << stats.max << "% -> " << o->primal << "\n";
    }
    std::cout << "dual of " << o->input << ": " << dual.vertexCount() << " vertices, " << dual.faceCount()
              << " faces -> " << o->output << "\n";
    return 0;
  };
}

const CommandRegistration registration{{"dual", "Polar dual of a polyhedral mesh and exploration of its spaces", setup, 63}};

}  // namespace
}  // namespace plano::cli
