// plano explore MESH --space S --eigenshapes K --band LO:HI --amplitude A -o OUT: add the
// eigenshapes of a linear space in a frequency band (linear-spaces paper, §3 band-pass).
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

namespace plano::cli {
namespace {

using namespace plano::subspace;

struct ExploreOptions {
  std::string input, output, report;
  LinearSpaceOptions linearSpace;
  Index eigenshapes = 10;
  std::string band;
  double amplitude = 0.05;
  bool keepPartial = false;
};

std::pair<Index, Index> parseBand(const std::string& text, Index count) {
  if (text.empty()) return {0, count};
  const auto colon = text.find(':');
  try {
    if (colon == std::string::npos) throw std::invalid_argument(text);
    return {static_cast<Index>(std::stoi(text.substr(0, colon))), static_cast<Index>(std::stoi(text.substr(colon + 1)))};
  } catch (const std::exception&) {
    throwUsage("--band must be LO:HI (eigenshape indices, HI exclusive), got '" + text + "'");
  }
}

RunFunction setup(CLI::App& app) {
  auto o = std::make_shared<ExploreOptions>();
  app.add_option("mesh", o->input, "Polyhedral mesh")->required();
  addLinearSpaceOptions(app, o->linearSpace);
  app.add_option("--eigenshapes", o->eigenshapes, "Number of eigenshapes to compute")
      ->capture_default_str()
      ->check(positiveNumber());
  app.add_option("--band", o->band, "Eigenshapes LO:HI (HI exclusive) to add; default all");
  app.add_option("--amplitude", o->amplitude, "Peak displacement per eigenshape, relative to the bounding-box diagonal")
      ->check(numberBetween(-kMaxAmplitude, kMaxAmplitude))
      ->capture_default_str();
  app.add_option("-o,--output", o->output, "Output mesh")->required();
  app.add_option("--report", o->report, "Write a JSON report to this file");
  addKeepPartialFlag(app, o->keepPartial);
  return [o](const GlobalOptions& global) {
    const auto backend = makeLinearSpaceBackend(global, "explore", "the reduced operator runs");
    const auto start = std::chrono::steady_clock::now();
    const PolygonMesh mesh = readMesh(o->input);
    LinearSpaceSettings settings = o->linearSpace.settings();
    const LinearSpace space = buildSpaceWithProgress(global, "explore", mesh, o->linearSpace.space,
                                                     o->linearSpace.assignment(mesh.faceCount()), settings);
    EigenshapeSettings es;
    es.count = o->eigenshapes;
    EigenshapeInfo info;
    const Eigenshapes shapes = computeEigenshapes(*backend, space.N, uniformLaplacian(mesh.faces, mesh.vertexCount()), es, &info);
    const auto [lo, hi] = parseBand(o->band, shapes.count());
    PolygonMesh out = mesh;
    out.vertices = bandPass(space.N, shapes, space.N.project(mesh.vertices), lo, hi, o->amplitude);
    const PlanarityStats stats = planarityStats(out);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nlohmann::json j = baseReport("explore", backend->name(), out, stats, seconds);
    j["space"] = o->linearSpace.space;
    j["dimension"] = space.dof.dimension;
    j["eigenshapes"] = shapes.count();
    j["frequencies"] = std::vector<double>(shapes.frequencies.data(), shapes.frequencies.data() + shapes.count());
    j["band"] = {lo, hi};
    j["amplitude"] = o->amplitude;
    j["eigensolver"] = info.dense ? "dense" : "spectra";
    j["subspace_residual"] = space.B.residual(out.vertices) / out.vertices.norm();
    finishCommand("explore", CommandOutcome{}, o->keepPartial, {{o->output, &out}}, j, o->report);
    std::cout << "added eigenshapes " << lo << ":" << hi << " of " << shapes.count() << " (" << o->linearSpace.space
              << " space, dimension " << space.dof.dimension << "), max planarity " << stats.max << "% -> "
              << o->output << "\n";
    return 0;
  };
}

const CommandRegistration registration{
    {"explore", "Add eigenshapes of a linear space in a frequency band (band-pass exploration)", setup, 61}};

}  // namespace
}  // namespace plano::cli
