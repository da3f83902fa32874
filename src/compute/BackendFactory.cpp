#include "compute/Backend.h"
#include "compute/cpu/CpuBackend.h"
#include "compute/vulkan/VulkanBackend.h"
#include "core/Error.h"

namespace plano::compute {

std::optional<DeviceTransfers> transfersSince(const std::optional<DeviceTransfers>& before,
                                              const std::optional<DeviceTransfers>& after) {
  if (!before || !after) return std::nullopt;
  return DeviceTransfers{after->uploadedBytes - before->uploadedBytes,
                         after->downloadedBytes - before->downloadedBytes, after->copies - before->copies};
}

namespace {

void checkSameVertexCount(const char* operation, const Positions& source, const Positions& target) {
  if (source.rows() != target.rows()) {
    throwUsage(std::string(operation) + ": source has " + std::to_string(source.rows()) + " vertices, target " +
               std::to_string(target.rows()));
  }
}

}  // namespace

void checkFitInputs(const Positions& source, const Positions& target) {
  checkSameVertexCount("fitProjectiveMaps", source, target);
}

void checkIdealMapInputs(const FaceList& faces, const Positions& source, std::span<const Eigen::Matrix4d> fitted,
                         const Positions* target) {
  if (fitted.size() != static_cast<std::size_t>(faces.size())) {
    throwUsage("closestIdealMaps: " + std::to_string(fitted.size()) + " maps for " + std::to_string(faces.size()) +
               " faces");
  }
  if (target) checkSameVertexCount("closestIdealMaps", source, *target);
}

void Backend::fitIdealMaps(const FaceList& faces, const Positions& source, const Positions& target, bool similar,
                           IdealMaps& out) {
  ProjectiveFits fits;
  fitProjectiveMaps(faces, source, target, fits);
  closestIdealMaps(faces, source, fits.maps, &target, similar, out);
}

void Backend::fitIdealMapsOnDevice(const FaceList& faces, const Positions& source, const Positions& target,
                                   bool similar, DeviceIdealMaps& out) {
  IdealMaps ideal;
  fitIdealMaps(faces, source, target, similar, ideal);
  const auto faceCount = static_cast<Index>(ideal.maps.size());
  Eigen::MatrixXd columns(4 * static_cast<Eigen::Index>(faceCount), 3);
  out.cornerProcrustes = 0;
  out.centroidsAtInfinity = 0;
  out.firstCentroidAtInfinity = -1;
  for (Index f = 0; f < faceCount; ++f) {
    columns.middleRows<4>(4 * static_cast<Eigen::Index>(f)) = ideal.maps[f].leftCols<3>();
    if (ideal.methods[f] == IdealMapMethod::CornerProcrustes) ++out.cornerProcrustes;
    if (ideal.methods[f] == IdealMapMethod::CentroidAtInfinity) {
      if (out.centroidsAtInfinity++ == 0) out.firstCentroidAtInfinity = f;
    }
  }
  out.linearColumns = DeviceMatrix(std::move(columns));
}

BackendChoice parseBackendChoice(const std::string& text) {
  if (text == "cpu") return BackendChoice::Cpu;
  if (text == "vulkan") return BackendChoice::Vulkan;
  if (text == "auto") return BackendChoice::Auto;
  throwUsage("unknown backend '" + text + "' (use cpu, vulkan or auto)");
}

std::unique_ptr<Backend> createBackend(BackendChoice choice, std::string* warnings) {
  if (choice == BackendChoice::Cpu) return std::make_unique<CpuBackend>();
  if (choice == BackendChoice::Vulkan) return createVulkanBackend(VulkanDevicePreference::Any);
  try {
    return createVulkanBackend(VulkanDevicePreference::RealGpuOnly);
  } catch (const Error& e) {
    if (warnings) *warnings += "warning: using the CPU backend: " + std::string(e.what()) + "\n";
    return std::make_unique<CpuBackend>();
  }
}

}  // namespace plano::compute
