#include "plano/Report.h"

#include "mesh/MeshIO.h"

namespace plano::cli {

nlohmann::json planarityJson(const PlanarityStats& stats) {
  return {{"max", stats.max},
          {"mean", stats.mean},
          {"p95", stats.p95},
          {"over_tolerance", stats.overTolerance},
          {"tolerance", stats.tolerance},
          {"max_run", stats.maxRun},
          {"max_plane_fit_residual", stats.maxPlaneFitResidual}};
}

nlohmann::json epsilonAttemptsJson(const std::vector<projective::EpsilonAttempt>& attempts) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& a : attempts) {
    list.push_back({{"epsilon", a.epsilon},
                    {"status", a.skipped ? "skipped" : projective::toString(a.status)},
                    {"method", a.skipped ? "none" : a.direct ? "equality" : "admm"},
                    {"iterations", a.iterations}});
  }
  return list;
}

namespace {
nlohmann::json transfersJson(const compute::DeviceTransfers& transfers) {
  return {{"uploaded_bytes", transfers.uploadedBytes},
          {"downloaded_bytes", transfers.downloadedBytes},
          {"copies", transfers.copies}};
}
}  // namespace

void addTransfers(nlohmann::json& entry, const std::optional<compute::DeviceTransfers>& transfers) {
  if (transfers) entry["device_transfers"] = transfersJson(*transfers);
}

void addTransferList(nlohmann::json& entry, const std::string& key,
                     const std::vector<std::optional<compute::DeviceTransfers>>& perIteration) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& transfers : perIteration) {
    if (!transfers) return;
    list.push_back(transfersJson(*transfers));
  }
  if (!list.empty()) entry[key] = std::move(list);
}

nlohmann::json baseReport(const std::string& command, const std::string& backend, const PolygonMesh& mesh,
                          const PlanarityStats& planarity, double seconds) {
  return {{"command", command},
          {"backend", backend},
          {"vertices", mesh.vertexCount()},
          {"faces", mesh.faceCount()},
          {"planarity", planarityJson(planarity)},
          {"seconds", seconds}};
}

namespace {
std::size_t written = 0;
}  // namespace

const char* failureStatus(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::Usage: return "usage_error";
    case ErrorKind::BadInput: return "bad_input";
    case ErrorKind::Numerical: return "numerical_failure";
    case ErrorKind::Device: return "device_failure";
  }
  return "error";
}

std::string reportText(const nlohmann::json& report) {
  return report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

void writeReport(const std::string& path, const nlohmann::json& report, OutputFiles with) {
  if (!path.empty()) with.add(path, reportText(report));
  with.commit();
  if (!path.empty()) ++written;
}

std::size_t reportsWritten() { return written; }

nlohmann::json failureReport(const std::string& command, const std::string& status, const std::string& reason) {
  return {{"command", command}, {"status", status}, {"reason", reason}, {"output_written", false}};
}

}  // namespace plano::cli
