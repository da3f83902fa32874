#include "compute/vulkan/VulkanBackend.h"

#include <algorithm>

#include "compute/vulkan/VulkanAdmm.h"
#include "compute/vulkan/VulkanMapPositions.h"
#include "compute/vulkan/VulkanContext.h"
#include "compute/vulkan/VulkanClosestRotations.h"
#include "compute/vulkan/VulkanIdealMaps.h"
#include "compute/vulkan/VulkanFacePlanarity.h"
#include "compute/vulkan/VulkanPcgSolver.h"
#include "compute/vulkan/VulkanProjectiveFit.h"
#include "compute/vulkan/VulkanReducedArap.h"
#include "compute/vulkan/VulkanReducedOperator.h"
#include "core/Error.h"

namespace plano::compute {

VulkanBackend::VulkanBackend(VulkanDevicePreference preference)
    : context_(std::make_unique<vk::Context>(vk::ContextSettings::fromEnvironment(
          preference == VulkanDevicePreference::RealGpuOnly ? vk::DeviceSelection::RealGpuOnly
                                                            : vk::DeviceSelection::Any))),
      residentMaps_(std::make_unique<vk::ResidentFaceMaps>()) {}

VulkanBackend::~VulkanBackend() = default;

std::string VulkanBackend::name() const { return "vulkan (" + context_->info().name + ")"; }

std::optional<DeviceTransfers> VulkanBackend::transfers() const {
  const vk::TransferCounts counts = context_->transfers();
  return DeviceTransfers{counts.uploadedBytes, counts.downloadedBytes, counts.uploads + counts.downloads};
}

void VulkanBackend::facePlanarity(const PolygonMesh& mesh, std::span<double> out) {
  if (!planarity_) planarity_ = std::make_unique<vk::FacePlanarityKernel>(*context_);
  planarity_->run(mesh, out);
}

void VulkanBackend::fitProjectiveMaps(const FaceList& faces, const Positions& source, const Positions& target,
                                      ProjectiveFits& out) {
  if (!projectiveFit_) projectiveFit_ = std::make_unique<vk::ProjectiveFitKernel>(*context_);
  projectiveFit_->run(faces, source, target, out);
}

void VulkanBackend::closestRotations(std::span<const Eigen::Matrix3d> matrices, std::span<Eigen::Matrix3d> rotations,
                                     std::span<Eigen::Vector3d> singularValues) {
  if (!rotations_) rotations_ = std::make_unique<vk::ClosestRotationsKernel>(*context_);
  rotations_->run(matrices, rotations, singularValues);
}

void VulkanBackend::closestIdealMaps(const FaceList& faces, const Positions& source,
                                     std::span<const Eigen::Matrix4d> fitted, const Positions* target, bool similar,
                                     IdealMaps& out) {
  if (!idealMaps_) idealMaps_ = std::make_unique<vk::IdealMapsKernel>(*context_, residentMaps_.get());
  // The fits of a deformation's local step come from this backend's fit kernel, whose
  // device arrays still hold them and the positions they were fitted to.
  const vk::Array<double>* residentFitted = projectiveFit_ ? projectiveFit_->mapsHolding(fitted) : nullptr;
  const vk::Array<double>* residentTarget =
      projectiveFit_ && target ? projectiveFit_->targetHolding(*target) : nullptr;
  idealMaps_->run(faces, source, fitted, target, similar, out, residentFitted, residentTarget);
}

void VulkanBackend::fitIdealMaps(const FaceList& faces, const Positions& source, const Positions& target, bool similar,
                                 IdealMaps& out) {
  if (!projectiveFit_) projectiveFit_ = std::make_unique<vk::ProjectiveFitKernel>(*context_);
  const vk::Array<double>* fits = projectiveFit_->runResident(faces, source, target);
  if (!fits) {  // no faces, or more maps than one binding holds
    Backend::fitIdealMaps(faces, source, target, similar, out);
    return;
  }
  if (!idealMaps_) idealMaps_ = std::make_unique<vk::IdealMapsKernel>(*context_, residentMaps_.get());
  idealMaps_->runOnResidentFits(faces, source, *fits, target, projectiveFit_->targetHolding(target), similar, out);
}

void VulkanBackend::fitIdealMapsOnDevice(const FaceList& faces, const Positions& source, const DeviceMatrix& target,
                                         bool similar, DeviceIdealMaps& out) {
  if (!projectiveFit_) projectiveFit_ = std::make_unique<vk::ProjectiveFitKernel>(*context_);
  const std::size_t faceCount = static_cast<std::size_t>(faces.size());
  const bool oneBinding = faceCount <= context_->info().maxStorageBufferRange / vk::kFaceMapBytes;
  const vk::Array<double>* residentTarget = residentPositions(target, source);
  Positions hostTarget;
  if (!residentTarget) hostTarget = target.values();
  const vk::Array<double>* fits = nullptr;
  if (oneBinding) {
    fits = residentTarget ? projectiveFit_->runResidentOn(faces, source, *residentTarget)
                          : projectiveFit_->runResident(faces, source, hostTarget);
  }
  if (!fits) {  // no faces, or more maps than one binding holds: the host keeps them
    Backend::fitIdealMapsOnDevice(faces, source, target, similar, out);
    return;
  }
  if (!idealMaps_) idealMaps_ = std::make_unique<vk::IdealMapsKernel>(*context_, residentMaps_.get());
  if (residentTarget) {
    idealMaps_->keepOnResidentFits(faces, source, *fits, nullptr, residentTarget, similar, out);
  } else {
    idealMaps_->keepOnResidentFits(faces, source, *fits, &hostTarget, projectiveFit_->targetHolding(hostTarget),
                                   similar, out);
  }
}

void VulkanBackend::fitProjectiveMapsOnDevice(const FaceList& faces, const Positions& source,
                                              const DeviceMatrix& target, double vanishingScale,
                                              DeviceProjectiveFits& out) {
  if (!projectiveFit_) projectiveFit_ = std::make_unique<vk::ProjectiveFitKernel>(*context_);
  const vk::Array<double>* residentTarget = residentPositions(target, source);
  Positions hostTarget;
  if (!residentTarget) hostTarget = target.values();
  if (projectiveFit_->keep(faces, source, residentTarget ? nullptr : &hostTarget, residentTarget, vanishingScale,
                           out)) {
    return;
  }
  // No faces, or more maps than one binding holds: the host keeps them.
  Backend::fitProjectiveMapsOnDevice(faces, source, target, vanishingScale, out);
}

const vk::Array<double>* VulkanBackend::residentPositions(const DeviceMatrix& positions, const Positions& like) const {
  // Positions this backend computed (mapPositions) are bound where they are.
  return positions.rows() == like.rows() && positions.cols() == 3
             ? vk::arrayOf(positions, *context_, vk::ArrayLayout::RowMajor)
             : nullptr;
}

void VulkanBackend::mapPositions(const FaceList& faces, const Positions& base, const VertexCorners& corners,
                                 const DeviceMatrix& mapColumns, const DeviceMatrix& cornerWeights,
                                 const DeviceMatrix& previous, MapPositions& out) {
  checkMapPositionInputs(faces, base, corners, mapColumns, cornerWeights, previous);
  const std::size_t range = context_->info().maxStorageBufferRange;
  const auto largest = std::max<std::size_t>({static_cast<std::size_t>(mapColumns.size()),
                                              static_cast<std::size_t>(base.size()), corners.corners.size()});
  if (largest > range / sizeof(double)) {  // more than one binding holds: on the host
    Backend::mapPositions(faces, base, corners, mapColumns, cornerWeights, previous, out);
    return;
  }
  if (!mapPositions_) mapPositions_ = std::make_unique<vk::MapPositionsKernel>(*context_);
  mapPositions_->run(faces, base, corners, mapColumns, cornerWeights, previous, out);
}

std::unique_ptr<SpdSolver> VulkanBackend::createSpdSolver(const SparseMatrix& A, const LinearSolverSettings& settings) {
  return std::make_unique<vk::PcgSolver>(*context_, A, settings);
}

std::unique_ptr<AdmmSolver> VulkanBackend::createAdmmSolver(const SparseMatrix& P, const SparseMatrix& C,
                                                           const AdmmSettings& settings) {
  auto kernels = std::make_unique<vk::AdmmKernels>(*context_, P, C, settings);
  // A global step's targets are often the ideal maps the ideal-map kernel just computed.
  kernels->bindResidentMaps(residentMaps_.get());
  return std::make_unique<AdmmSolver>(std::move(kernels), P.rows(), C.rows(), settings);
}

Eigen::MatrixXd VulkanBackend::reducedOperator(const SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates) {
  if (!reducedOperator_) reducedOperator_ = std::make_unique<vk::ReducedOperatorKernel>(*context_);
  return reducedOperator_->run(S, N, coordinates);
}

std::unique_ptr<ReducedArapKernels> VulkanBackend::createReducedArapKernels(
    const std::function<ReducedArapProblem()>& problem) {
  return std::make_unique<vk::ReducedArapKernels>(*context_, problem());
}

std::unique_ptr<Backend> createVulkanBackend(VulkanDevicePreference preference) {
  return std::make_unique<VulkanBackend>(preference);
}

}  // namespace plano::compute
