#pragma once
// The Vulkan compute backend: GLSL kernels from shaders/, embedded as SPIR-V, run on
// the device of a Context that the backend owns (no process-global device state).
#include <memory>

#include "compute/Backend.h"

namespace plano::vk {
class Context;
class FacePlanarityKernel;
class ProjectiveFitKernel;
class ClosestRotationsKernel;
class IdealMapsKernel;
class ResidentFaceMaps;
class MapPositionsKernel;
class ReducedOperatorKernel;
template <class T>
class Array;
}  // namespace plano::vk

namespace plano::compute {

enum class VulkanDevicePreference {
  Any,          ///< A discrete/integrated GPU when present, else a CPU device (lavapipe).
  RealGpuOnly,  ///< Refuse CPU implementations (used by --backend auto).
};

class VulkanBackend final : public Backend {
 public:
  /// Create the context (see createVulkanBackend); kernels' pipelines are built on first use.
  explicit VulkanBackend(VulkanDevicePreference preference);
  ~VulkanBackend() override;

  BackendKind kind() const override { return BackendKind::Vulkan; }
  std::string name() const override;

  void facePlanarity(const PolygonMesh& mesh, std::span<double> out) override;
  void fitProjectiveMaps(const FaceList& faces, const Positions& source, const Positions& target,
                         ProjectiveFits& out) override;
  void closestRotations(std::span<const Eigen::Matrix3d> matrices, std::span<Eigen::Matrix3d> rotations,
                        std::span<Eigen::Vector3d> singularValues) override;
  void closestIdealMaps(const FaceList& faces, const Positions& source, std::span<const Eigen::Matrix4d> fitted,
                        const Positions* target, bool similar, IdealMaps& out) override;
  /// The fits stay on the device: only the ideal maps come back.
  void fitIdealMaps(const FaceList& faces, const Positions& source, const Positions& target, bool similar,
                    IdealMaps& out) override;
  /// The fits and the ideal maps stay on the device (vk::ResidentFaceMaps): three tallies
  /// come back, and the maps only when their values are read.
  /// A target of this backend's mapPositions is bound where it is.
  void fitIdealMapsOnDevice(const FaceList& faces, const Positions& source, const DeviceMatrix& target, bool similar,
                            DeviceIdealMaps& out) override;
  /// The fits, their first three columns and the induced scales stay in the fit kernel's
  /// arrays (vk::ProjectiveFitKernel::keep): two tallies come back. A target of this
  /// backend's mapPositions is bound where it is.
  void fitProjectiveMapsOnDevice(const FaceList& faces, const Positions& source, const DeviceMatrix& target,
                                 double vanishingScale, DeviceProjectiveFits& out) override;
  /// On the device (vk::MapPositionsKernel): two scalars come back, the positions stay.
  void mapPositions(const FaceList& faces, const Positions& base, const VertexCorners& corners,
                    const DeviceMatrix& mapColumns, const DeviceMatrix& cornerWeights, const DeviceMatrix& previous,
                    MapPositions& out) override;
  /// A Jacobi-preconditioned CG solver on the device (vk::PcgSolver). It uses this
  /// backend's device: it must not outlive the backend.
  std::unique_ptr<SpdSolver> createSpdSolver(const SparseMatrix& A, const LinearSolverSettings& settings) override;

  /// The ADMM iteration on the device (vk::AdmmKernels): only the checks' inf-norms come
  /// back to the host. Like the SPD solver, it must not outlive the backend.
  std::unique_ptr<AdmmSolver> createAdmmSolver(const SparseMatrix& P, const SparseMatrix& C,
                                               const AdmmSettings& settings) override;

  /// Subspace ASAP/ARAP iterations on the device (vk::ReducedArapKernels): a few scalars
  /// per iteration come back. Must not outlive the backend.
  std::unique_ptr<ReducedArapKernels> createReducedArapKernels(
      const std::function<ReducedArapProblem()>& problem) override;

  /// Basis and S up once, the d x d result down (vk::ReducedOperatorKernel).
  Eigen::MatrixXd reducedOperator(const SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates) override;

  std::optional<DeviceTransfers> transfers() const override;

  /// The device context (device properties, validation messages).
  vk::Context& context() { return *context_; }

 private:
  /// The array of `positions` when it holds this backend's positions of as many vertices
  /// as `like` (mapPositions'); else null.
  const vk::Array<double>* residentPositions(const DeviceMatrix& positions, const Positions& like) const;

  std::unique_ptr<vk::Context> context_;
  std::unique_ptr<vk::FacePlanarityKernel> planarity_;
  std::unique_ptr<vk::ProjectiveFitKernel> projectiveFit_;
  std::unique_ptr<vk::ClosestRotationsKernel> rotations_;
  /// The ideal maps idealMaps_ keeps on the device, for the ADMM solvers' q (declared
  /// before the kernel, which releases it when destroyed).
  std::unique_ptr<vk::ResidentFaceMaps> residentMaps_;
  std::unique_ptr<vk::IdealMapsKernel> idealMaps_;
  std::unique_ptr<vk::MapPositionsKernel> mapPositions_;
  std::unique_ptr<vk::ReducedOperatorKernel> reducedOperator_;
};

/// Create the Vulkan backend. The device can be forced with the environment variable
/// PLANO_VULKAN_DEVICE (index or a substring of the device name); PLANO_VULKAN_VALIDATION=1
/// turns the validation layers on. Throws Error(Device) with the reason when no suitable
/// device exists (no loader or driver, no device, no shaderFloat64).
std::unique_ptr<Backend> createVulkanBackend(VulkanDevicePreference preference);

}  // namespace plano::compute
