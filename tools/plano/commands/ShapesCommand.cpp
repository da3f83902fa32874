// plano shapes MESH --space S --kind sparse|fundamental --vertex V -o OUT: a sparse shape
// (OMP) or a fundamental shape of a vertex (linear-spaces paper, §3), added to the mesh.
#include <chrono>
#include <iostream>

#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "plano/Command.h"
#include "plano/CommandOutcome.h"
#include "plano/LinearSpaceOptions.h"
#include "plano/Report.h"
#include "subspace/FundamentalShapes.h"
#include "subspace/LinearSpace.h"
#include "subspace/MeshLaplacian.h"
#include "subspace/SparseShapes.h"
#include "subspace/VertexNormals.h"

namespace plano::cli {
namespace {

using namespace plano::subspace;

struct ShapesOptions {
  std::string input, output, report;
  LinearSpaceOptions linearSpace;
  std::string kind = "fundamental";
  Index vertex = 0;
  std::vector<double> direction;
  double amplitude = 0.05;
  double smoothness = 1.0;
  Index maxSupport = 64;
  bool keepPartial = false;
};

RunFunction setup(CLI::App& app) {
  auto o = std::make_shared<ShapesOptions>();
  app.add_option("mesh", o->input, "Polyhedral mesh")->required();
  addLinearSpaceOptions(app, o->linearSpace);
  app.add_option("--kind", o->kind, "sparse | fundamental")
      ->check(CLI::IsMember({"sparse", "fundamental"}))
      ->capture_default_str();
  app.add_option("--vertex", o->vertex, "The vertex the shape moves")->required();
  app.add_option("--direction", o->direction, "Direction X,Y,Z (default: the vertex normal)")->delimiter(',')->expected(3);
  app.add_option("--amplitude", o->amplitude, "Peak displacement relative to the bounding-box diagonal")
      ->check(numberBetween(-kMaxAmplitude, kMaxAmplitude))
      ->capture_default_str();
  app.add_option("--smoothness", o->smoothness, "lambda of the fundamental shape")->capture_default_str();
  app.add_option("--max-support", o->maxSupport, "Sparse shape: most vertices that may move (the seed included)")
      ->check(CLI::Range(Index{1}, Index{1'000'000'000}))
      ->capture_default_str();
  app.add_option("-o,--output", o->output, "Output mesh")->required();
  app.add_option("--report", o->report, "Write a JSON report to this file");
  addKeepPartialFlag(app, o->keepPartial);
  return [o](const GlobalOptions& global) {
    // Sparse shapes (OMP on B) compute on the CPU: each step works on the few hundred rows
    // around its support. A fundamental shape's reduced operator runs on the backend.
    std::unique_ptr<compute::Backend> backend;
    const std::string backendName = o->kind == "sparse"
                                        ? warnComputesOnCpu(global, "shapes --kind sparse",
                                                            "each OMP step works on the few hundred rows around its "
                                                            "support, too little work for a device")
                                                        : (backend = makeLinearSpaceBackend(global, "shapes", "the reduced operator runs"))->name();
    const auto start = std::chrono::steady_clock::now();
    const PolygonMesh mesh = readMesh(o->input);
    if (o->vertex < 0 || o->vertex >= mesh.vertexCount()) {
      throwUsage("--vertex " + std::to_string(o->vertex) + " is out of range (mesh has " +
                 std::to_string(mesh.vertexCount()) + " vertices)");
    }
    const Eigen::Vector3d direction = o->direction.size() == 3
                                          ? Eigen::Vector3d(o->direction[0], o->direction[1], o->direction[2])
                                          : vertexNormal(mesh, o->vertex);
    LinearSpaceSettings settings = o->linearSpace.settings();
    const auto spaces = o->linearSpace.assignment(mesh.faceCount());
    nlohmann::json extra;
    Positions shape;
    Positions base = mesh.vertices;
    if (o->kind == "sparse") {
      // Sparse shapes need B only: no basis, so this also runs on large meshes.
      const ConstraintMatrix B = buildConstraintMatrix(mesh, spaces, settings.constraints);
      SparseShapeSettings ss;
      ss.maxSupportVertices = o->maxSupport;
      SparseShapeInfo info;
      shape = sparseShape(B, o->vertex, direction, ss, &info);
      extra = {{"status", info.status == SparseShapeStatus::Exact ? "exact" : "approximate"},
               {"iterations", info.iterations},
               {"support_vertices", info.supportVertices},
               {"residual", info.residual},
               {"initial_residual", info.initialResidual}};
      std::cout << "sparse shape of vertex " << o->vertex << ": " << extra["status"].get<std::string>() << ", "
                << info.supportVertices << " vertices move, ||BX||/||X|| = " << info.residual << "\n";
    } else {
      const LinearSpace space = buildSpaceWithProgress(global, "shapes", mesh, o->linearSpace.space, spaces, settings);
      FundamentalShapeSettings fs;
      fs.smoothness = o->smoothness;
      shape = fundamentalShape(*backend, space.N, uniformLaplacian(mesh.faces, mesh.vertexCount()), o->vertex, direction, fs);
      base = space.N.project(mesh.vertices);
      extra = {{"dimension", space.dof.dimension}, {"smoothness", o->smoothness}};
      std::cout << "fundamental shape of vertex " << o->vertex << " in the " << o->linearSpace.space << " space (dimension "
                << space.dof.dimension << ")\n";
    }
    const double peak = shape.rowwise().norm().maxCoeff();
    PolygonMesh out = mesh;
    out.vertices = base + (peak > 0.0 ? o->amplitude * boundingBoxDiagonal(mesh.vertices) / peak : 0.0) * shape;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nlohmann::json j = baseReport("shapes", backendName, out, planarityStats(out), seconds);
    j["space"] = o->linearSpace.space;
    j["kind"] = o->kind;
    j["vertex"] = o->vertex;
    j["direction"] = {direction[0], direction[1], direction[2]};
    j["shape"] = extra;
    finishCommand("shapes", CommandOutcome{}, o->keepPartial, {{o->output, &out}}, j, o->report);
    return 0;
  };
}

const CommandRegistration registration{
    {"shapes", "Sparse (OMP) or fundamental shape of a vertex in a linear space", setup, 62}};

}  // namespace
}  // namespace plano::cli
