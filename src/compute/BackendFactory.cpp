#include "compute/Backend.h"

#include <cmath>

#include "compute/cpu/CpuBackend.h"
#include "compute/vulkan/VulkanBackend.h"
#include "core/Error.h"
#include "mesh/Planarity.h"

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

void Backend::fitIdealMapsOnDevice(const FaceList& faces, const Positions& source, const DeviceMatrix& target,
                                   bool similar, DeviceIdealMaps& out) {
  IdealMaps ideal;
  fitIdealMaps(faces, source, Positions(target.values()), similar, ideal);
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

void Backend::fitProjectiveMapsOnDevice(const FaceList& faces, const Positions& source, const DeviceMatrix& target,
                                        double vanishingScale, DeviceProjectiveFits& out) {
  ProjectiveFits fits;
  fitProjectiveMaps(faces, source, Positions(target.values()), fits);
  const Index faceCount = faces.size();
  Eigen::MatrixXd columns(4 * static_cast<Eigen::Index>(faceCount), 3);
  Eigen::MatrixXd scales(faces.cornerCount(), 1);
  out.nonPositiveScales = 0;
  out.firstVanishingCorner = -1;
  for (Index f = 0; f < faceCount; ++f) {
    const Eigen::Matrix4d& map = fits.maps[static_cast<std::size_t>(f)];
    columns.middleRows<4>(4 * static_cast<Eigen::Index>(f)) = map.leftCols<3>();
    // The fit's own scales are taken on the plane-projected corners; these on `source`.
    for (Index c = faces.offsets()[f]; c < faces.offsets()[f + 1]; ++c) {
      const Index v = faces.indices()[c];
      const double s = Eigen::RowVector4d(source(v, 0), source(v, 1), source(v, 2), 1.0).dot(map.col(3));
      scales(c, 0) = s;
      if (!(s > 0.0)) ++out.nonPositiveScales;
      if (!(std::abs(s) > vanishingScale) && out.firstVanishingCorner < 0) out.firstVanishingCorner = c;
    }
  }
  out.linearColumns = DeviceMatrix(std::move(columns));
  out.reciprocalScales = DeviceMatrix(std::move(scales));
}

void checkMapPositionInputs(const FaceList& faces, const Positions& base, const VertexCorners& corners,
                            const DeviceMatrix& mapColumns, const DeviceMatrix& cornerWeights,
                            const DeviceMatrix& previous) {
  const auto vertexCount = static_cast<std::size_t>(base.rows());
  if (corners.offsets.size() != vertexCount + 1 || corners.corners.size() != corners.cornerFace.size() ||
      static_cast<std::size_t>(corners.offsets.back()) != corners.corners.size() ||
      corners.cornerFace.size() != static_cast<std::size_t>(faces.cornerCount())) {
    throwUsage("mapPositions: vertex corner tables of the wrong sizes for " + std::to_string(vertexCount) +
               " vertices and " + std::to_string(faces.cornerCount()) + " corners");
  }
  if (mapColumns.rows() != 4 * static_cast<Eigen::Index>(faces.size()) || mapColumns.cols() != 3) {
    throwUsage("mapPositions: map columns of " + std::to_string(mapColumns.rows()) + " x " +
               std::to_string(mapColumns.cols()) + " for " + std::to_string(faces.size()) + " faces");
  }
  if (cornerWeights.size() != 0 && (cornerWeights.rows() != faces.cornerCount() || cornerWeights.cols() != 1)) {
    throwUsage("mapPositions: corner weights of " + std::to_string(cornerWeights.rows()) + " x " +
               std::to_string(cornerWeights.cols()) + " for " + std::to_string(faces.cornerCount()) + " corners");
  }
  if (previous.rows() != base.rows() || previous.cols() != 3) {
    throwUsage("mapPositions: previous positions of " + std::to_string(previous.rows()) + " rows for " +
               std::to_string(vertexCount) + " vertices");
  }
}

void Backend::mapPositions(const FaceList& faces, const Positions& base, const VertexCorners& corners,
                           const DeviceMatrix& mapColumns, const DeviceMatrix& cornerWeights,
                           const DeviceMatrix& previous, MapPositions& out) {
  checkMapPositionInputs(faces, base, corners, mapColumns, cornerWeights, previous);
  const Eigen::MatrixXd& X = mapColumns.values();
  const bool weighted = cornerWeights.size() != 0;
  const Eigen::MatrixXd& weights = weighted ? cornerWeights.values() : X;  // read only when weighted
  Positions positions = base;
  for (Eigen::Index v = 0; v < base.rows(); ++v) {
    const Index begin = corners.offsets[v];
    const Index end = corners.offsets[v + 1];
    if (begin == end) continue;
    const Eigen::RowVector4d p(base(v, 0), base(v, 1), base(v, 2), 1.0);
    Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
    for (Index k = begin; k < end; ++k) {
      const Index corner = corners.corners[k];
      const Eigen::Matrix<double, 4, 3> M = X.middleRows<4>(4 * static_cast<Eigen::Index>(corners.cornerFace[corner]));
      if (weighted) {
        sum += (p * M) / weights(corner, 0);
      } else {
        sum += p * M;
      }
    }
    positions.row(v) = sum / static_cast<double>(end - begin);
  }
  if (!positions.allFinite()) throwNumerical("mapPositions: a vertex position from the maps is not finite");
  out.displacement = maxVertexDistance(Positions(previous.values()), positions);
  out.maxPlanarity = planarityStats(PolygonMesh{positions, faces}).max;
  out.positions = DeviceMatrix(Eigen::MatrixXd(positions));
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
