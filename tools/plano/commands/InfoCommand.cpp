// plano info MESH [--json] [--tolerance PERCENT]: counts, topology, validation and
// planarity. An invalid mesh is bad input (exit 3, the problems on stderr); warnings
// (e.g. isolated vertices) go to stderr and do not change the exit code.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <map>

#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "mesh/Planarity.h"
#include "mesh/Topology.h"
#include "mesh/Validation.h"
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

nlohmann::json issuesJson(const ValidationReport& report, Severity severity) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& issue : report.issues) {
    if (issue.severity != severity) continue;
    nlohmann::json j = {{"kind", toString(issue.kind)}, {"message", issue.message}};
    if (issue.face >= 0) j["face"] = issue.face;
    if (issue.vertex >= 0) j["vertex"] = issue.vertex;
    list.push_back(std::move(j));
  }
  return list;
}

nlohmann::json validationJson(const ValidationReport& report) {
  const char* status = report.status == ValidationStatus::Valid               ? "valid"
                       : report.status == ValidationStatus::ValidWithWarnings ? "valid_with_warnings"
                                                                              : "invalid";
  return {{"status", status},
          {"errors", issuesJson(report, Severity::Error)},
          {"warnings", issuesJson(report, Severity::Warning)},
          {"error_count", report.errorCount},
          {"warning_count", report.warningCount}};
}

nlohmann::json describe(const PolygonMesh& mesh, const MeshTopology& topology, const ValidationReport& validation,
                        const PlanarityStats& stats, const std::string& backend, double seconds) {
  nlohmann::json j = baseReport("info", backend, mesh, stats, seconds);
  std::map<Index, Index> histogram;
  for (Index f = 0; f < mesh.faceCount(); ++f) ++histogram[mesh.faces.degree(f)];
  nlohmann::json degrees = nlohmann::json::object();
  for (const auto& [degree, count] : histogram) degrees[std::to_string(degree)] = count;
  j["corners"] = mesh.faces.cornerCount();
  j["edges"] = topology.edgeCount();
  j["face_degrees"] = degrees;
  j["boundaries"] = topology.boundaryCount();
  j["boundary_edges"] = topology.boundaryEdgeCount();
  j["boundary_vertices"] = topology.boundaryVertexCount();
  j["isolated_vertices"] = topology.isolatedVertexCount();
  j["components"] = topology.componentCount();
  j["euler_characteristic"] = topology.eulerCharacteristic();
  const auto genus = topology.genus();
  j["genus"] = genus ? nlohmann::json(*genus) : nlohmann::json(nullptr);
  j["bounding_box_diagonal"] = boundingBoxDiagonal(mesh.vertices);
  j["validation"] = validationJson(validation);
  return j;
}

void printText(const nlohmann::json& j, const PolygonMesh& mesh, const std::string& input) {
  std::cout << input << "\n";
  std::cout << "  vertices " << j["vertices"] << ", edges " << j["edges"] << ", faces " << j["faces"] << ", corners "
            << j["corners"] << "\n";
  std::map<Index, Index> histogram;  // numeric order (the JSON object sorts its keys as text)
  for (Index f = 0; f < mesh.faceCount(); ++f) ++histogram[mesh.faces.degree(f)];
  std::cout << "  face degrees:";
  for (const auto& [degree, count] : histogram) std::cout << " " << degree << "-gons " << count;
  std::cout << "\n";
  std::cout << "  boundaries " << j["boundaries"] << " (" << j["boundary_vertices"] << " vertices), components "
            << j["components"] << ", Euler characteristic " << j["euler_characteristic"] << ", genus "
            << (j["genus"].is_null() ? std::string("undefined") : j["genus"].dump()) << "\n";
  const auto& p = j["planarity"];
  std::cout << std::setprecision(4) << "  planarity %: max " << p["max"].get<double>() << ", mean "
            << p["mean"].get<double>() << ", p95 " << p["p95"].get<double>() << ", over " << p["tolerance"].get<double>()
            << "%: " << p["over_tolerance"] << " faces\n";
  const auto& v = j["validation"];
  std::cout << "  validation: " << v["status"].get<std::string>() << " (" << v["warning_count"] << " warnings)\n";
}

RunFunction setup(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  app.add_option("mesh", options->input, "Mesh file (.obj, .off, .ply)")->required();
  app.add_flag("--json", options->json, "Print the report as JSON on stdout");
  app.add_option("--tolerance", options->tolerance, "Planarity tolerance in percent for the over-tolerance count")
      ->capture_default_str()
      ->check(positiveNumber());
  app.add_option("--report", options->report, "Also write the JSON report to this file");
  return [options](const GlobalOptions& global) {
    const auto start = std::chrono::steady_clock::now();
    // Read without validating, so that every problem is listed rather than the first few.
    ReadOptions read;
    read.validate = false;
    std::vector<std::string> readWarnings;
    read.warnings = &readWarnings;
    const PolygonMesh mesh = readMesh(options->input, read);
    for (const auto& w : readWarnings) std::cerr << "plano: warning: " << w << "\n";
    const ValidationReport validation = validate(mesh);
    std::size_t shownWarnings = 0;
    for (const auto& issue : validation.issues) {
      if (issue.severity != Severity::Warning) continue;
      std::cerr << "plano: warning: " << options->input << ": " << issue.message << "\n";
      ++shownWarnings;
    }
    if (validation.warningCount > shownWarnings) {
      std::cerr << "plano: warning: " << options->input << ": " << validation.warningCount - shownWarnings
                << " more warnings\n";
    }
    requireValid(validation, options->input);  // exit 3 with the errors on stderr

    const MeshTopology topology(mesh.faces, mesh.vertexCount());
    auto backend = makeBackend(global);
    std::vector<double> values(mesh.faceCount());
    backend->facePlanarity(mesh, values);
    PlanarityStats stats = summarizePlanarity(values, options->tolerance);
    const PlanarityStats full = planarityStats(mesh, options->tolerance);
    stats.maxRun = full.maxRun;
    stats.maxPlaneFitResidual = full.maxPlaneFitResidual;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const nlohmann::json j = describe(mesh, topology, validation, stats, backend->name(), seconds);
    if (options->json) {
      std::cout << reportText(j) << std::flush;
    } else {
      printText(j, mesh, options->input);
    }
    writeReport(options->report, j);
    return 0;
  };
}

const CommandRegistration registration{{"info", "Counts, topology, validation and planarity of a mesh", setup, 10}};

}  // namespace
}  // namespace plano::cli
