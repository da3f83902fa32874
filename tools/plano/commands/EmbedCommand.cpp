// plano embed TOPOLOGY -o OUT [--lift eigenshape|handle|none]: an initial polyhedral mesh from
// the connectivity of a disk mesh: Tutte embedding, then height from the affine space
// (linear-spaces paper, §4 "Creating an initial PM" and "Design pipeline").
#include <chrono>
#include <iostream>

#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "plano/Command.h"
#include "plano/CommandOutcome.h"
#include "plano/Report.h"
#include "subspace/AffineLifting.h"
#include "subspace/TutteEmbedding.h"

namespace plano::cli {
namespace {

using namespace plano::subspace;

struct EmbedOptions {
  std::string input, output, report;
  std::string lift = "eigenshape";
  double height = 0.25;
  Index eigenshape = 0;
  Index vertex = -1;
  bool keepPartial = false;
};

RunFunction setup(CLI::App& app) {
  auto o = std::make_shared<EmbedOptions>();
  app.add_option("topology", o->input, "Mesh whose connectivity is used (positions are ignored); a disk")->required();
  app.add_option("-o,--output", o->output, "Output mesh")->required();
  app.add_option("--lift", o->lift, "eigenshape | handle | none")
      ->check(CLI::IsMember({"eigenshape", "handle", "none"}))
      ->capture_default_str();
  app.add_option("--height", o->height, "Largest height relative to the bounding-box diagonal")
      ->check(numberBetween(-kMaxAmplitude, kMaxAmplitude))
      ->capture_default_str();
  app.add_option("--eigenshape", o->eigenshape, "Which non-planar lifting eigenshape (0 = lowest)")->capture_default_str();
  const CLI::Option* vertex =
      app.add_option("--vertex", o->vertex, "With --lift handle: the handle vertex (default: the one nearest the centre)")
          ->check(nonNegativeNumber());
  app.add_option("--report", o->report, "Write a JSON report to this file");
  addKeepPartialFlag(app, o->keepPartial);
  return [o, vertex](const GlobalOptions& global) {
    if (vertex->count() > 0 && o->lift != "handle") {
      throwUsage("embed: --vertex is the handle of --lift handle (got --lift " + o->lift + ")");
    }
    const auto backend =
        makeLinearSpaceBackend(global, "embed", "the Tutte solve and the lifting's reduced operator run");
    const auto start = std::chrono::steady_clock::now();
    const PolygonMesh topology = readMesh(o->input);
    // Before the embedding, as shapes --vertex: a usage error, not bad input after the work.
    if (vertex->count() > 0 && o->vertex >= topology.vertexCount()) {
      throwUsage("--vertex " + std::to_string(o->vertex) + " is out of range (" + o->input + " has " +
                 std::to_string(topology.vertexCount()) + " vertices)");
    }
    TutteInfo tutte;
    PolygonMesh out{tutteEmbedding(*backend, topology.faces, topology.vertexCount(), {}, &tutte), topology.faces};
    progress(global, "Tutte embedding: " + std::to_string(tutte.boundaryVertices) + " boundary vertices, " +
                         std::to_string(tutte.flippedFaces) + " flipped faces");
    LiftInfo lift;
    if (o->lift != "none") {
      LiftSettings settings;
      settings.kind = o->lift == "handle" ? LiftKind::Handle : LiftKind::Eigenshape;
      settings.height = o->height;
      settings.eigenshape = o->eigenshape;
      settings.handleVertex = o->vertex;
      out = liftWithAffineSpace(*backend, out, settings, &lift);
    }
    const PlanarityStats stats = planarityStats(out);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nlohmann::json j = baseReport("embed", backend->name(), out, stats, seconds);
    j["boundary_vertices"] = tutte.boundaryVertices;
    j["flipped_faces"] = tutte.flippedFaces;
    j["lift"] = o->lift;
    j["liftings"] = lift.liftings;
    j["max_height"] = lift.maxHeight;
    finishCommand("embed", CommandOutcome{}, o->keepPartial, {{o->output, &out}}, j, o->report);
    std::cout << "embedded " << o->input << " (" << tutte.flippedFaces << " flipped faces), lift " << o->lift
              << ", max height " << lift.maxHeight << ", max planarity " << stats.max << "% -> " << o->output << "\n";
    return 0;
  };
}

const CommandRegistration registration{
    {"embed", "Initial polyhedral mesh from a disk topology: Tutte embedding and affine lifting", setup, 64}};

}  // namespace
}  // namespace plano::cli
