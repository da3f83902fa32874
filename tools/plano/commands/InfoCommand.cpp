// plano info MESH [--json] [--tolerance PERCENT]: counts, face degrees and planarity.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <map>

#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "plano/Command.h"
#include "plano/Report.h"

namespace plano::cli {
namespace {

struct InfoOptions {
  std::string input;
  bool json = false;
  double tolerance = 1.0;
  std::string report;
};

nlohmann::json describe(const PolygonMesh& mesh, const PlanarityStats& stats, const std::string& backend,
                        double seconds) {
  nlohmann::json j = baseReport("info", backend, mesh, stats, seconds);
  std::map<Index, Index> histogram;
  for (Index f = 0; f < mesh.faceCount(); ++f) ++histogram[mesh.faces.degree(f)];
  nlohmann::json degrees = nlohmann::json::object();
  for (const auto& [degree, count] : histogram) degrees[std::to_string(degree)] = count;
  j["corners"] = mesh.faces.cornerCount();
  j["face_degrees"] = degrees;
  j["bounding_box_diagonal"] = boundingBoxDiagonal(mesh.vertices);
  return j;
}

void printText(const nlohmann::json& j, const std::string& input) {
  std::cout << input << "\n";
  std::cout << "  vertices " << j["vertices"] << ", faces " << j["faces"] << ", corners " << j["corners"] << "\n";
  std::cout << "  face degrees:";
  for (const auto& [degree, count] : j["face_degrees"].items()) std::cout << " " << degree << "-gons " << count;
  std::cout << "\n";
  const auto& p = j["planarity"];
  std::cout << std::setprecision(4) << "  planarity %: max " << p["max"].get<double>() << ", mean "
            << p["mean"].get<double>() << ", p95 " << p["p95"].get<double>() << ", over " << p["tolerance"].get<double>()
            << "%: " << p["over_tolerance"] << " faces\n";
}

RunFunction setup(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  app.add_option("mesh", options->input, "Mesh file (.obj, .off, .ply)")->required();
  app.add_flag("--json", options->json, "Print the report as JSON on stdout");
  app.add_option("--tolerance", options->tolerance, "Planarity tolerance in percent for the over-tolerance count")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--report", options->report, "Also write the JSON report to this file");
  return [options](const GlobalOptions& global) {
    const auto start = std::chrono::steady_clock::now();
    const PolygonMesh mesh = readMesh(options->input);
    auto backend = makeBackend(global);
    std::vector<double> values(mesh.faceCount());
    backend->facePlanarity(mesh, values);
    PlanarityStats stats = summarizePlanarity(values, options->tolerance);
    const PlanarityStats full = planarityStats(mesh, options->tolerance);
    stats.maxRun = full.maxRun;
    stats.maxPlaneFitResidual = full.maxPlaneFitResidual;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const nlohmann::json j = describe(mesh, stats, backend->name(), seconds);
    if (options->json) {
      std::cout << j.dump(2) << std::endl;
    } else {
      printText(j, options->input);
    }
    writeReport(options->report, j);
    return 0;
  };
}

const CommandRegistration registration{{"info", "Counts, topology, validation and planarity of a mesh", setup, 10}};

}  // namespace
}  // namespace plano::cli
