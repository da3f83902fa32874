// plano generate KIND [-n N] -o OUT: parametric meshes for demos, tests and benchmarks.
#include <chrono>
#include <iostream>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "plano/Command.h"
#include "plano/CommandOutcome.h"
#include "plano/GenerateSize.h"
#include "plano/Report.h"

namespace plano::cli {
namespace {

struct GenerateOptions {
  std::string kind;
  Index n = 8;
  std::string output;
  std::string report;
};

RunFunction setup(CLI::App& app) {
  auto options = std::make_shared<GenerateOptions>();
  std::string kinds;
  for (const auto& k : generate::generatorKinds()) kinds += "\n  " + k.name + ": " + k.description;
  app.add_option("kind", options->kind, "Mesh kind:" + kinds)->required();
  app.add_option("-n,--resolution", options->n, "Resolution (quads per side, rings, ...)")
      ->capture_default_str()
      ->check(CLI::Range(0, 4096));
  app.add_option("-o,--output", options->output, "Output mesh file (.obj, .off, .ply)")->required();
  app.add_option("--report", options->report, "Write a JSON report to this file");
  return [options](const GlobalOptions& global) {
    const auto start = std::chrono::steady_clock::now();
    requireGeneratable(options->kind, options->n);
    const PolygonMesh mesh = generate::byName(options->kind, options->n);
    const PlanarityStats stats = planarityStats(mesh);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // The mesh and the report together, and neither after Ctrl-C.
    finishCommand("generate", CommandOutcome{}, false, {{options->output, &mesh}},
                  baseReport("generate", "cpu", mesh, stats, seconds), options->report);
    progress(global, "generated " + options->kind + ": " + std::to_string(mesh.vertexCount()) + " vertices, " +
                         std::to_string(mesh.faceCount()) + " faces, max planarity " + std::to_string(stats.max) +
                         "% -> " + options->output);
    return 0;
  };
}

const CommandRegistration registration{{"generate", "Generate a parametric polygon mesh", setup, 20}};

}  // namespace
}  // namespace plano::cli
