#pragma once
// Positions from face maps (affine, or projective with their corner weights) on the device (compute::Backend::mapPositions):
// shaders/map_positions.comp forms them with each vertex's distance to its previous
// position, shaders/face_planarity.comp the planarity of every face there, and two max-abs
// reductions leave the displacement and the largest planarity: two scalars come back. The
// positions stay in one of two arrays (the other holds the previous positions a loop
// passes next time), as device matrices the fit kernels bind.
#include <memory>

#include "compute/Backend.h"
#include "compute/vulkan/VulkanDeviceMatrix.h"
#include "compute/vulkan/VulkanLinearAlgebra.h"

namespace plano::vk {

class MapPositionsKernel {
 public:
  explicit MapPositionsKernel(Context& context);
  ~MapPositionsKernel();
  MapPositionsKernel(const MapPositionsKernel&) = delete;
  MapPositionsKernel& operator=(const MapPositionsKernel&) = delete;

  /// compute::Backend::mapPositions (its checks done by the caller). `mapColumns`,
  /// `cornerWeights` and `previous` are bound where they are device matrices of this
  /// context (the ADMM's solution, the fit kernel's induced scales, this kernel's last
  /// positions), else uploaded.
  void run(const FaceList& faces, const Positions& base, const compute::VertexCorners& corners,
           const compute::DeviceMatrix& mapColumns, const compute::DeviceMatrix& cornerWeights,
           const compute::DeviceMatrix& previous, compute::MapPositions& out);

 private:
  Context& context_;
  LinearAlgebra algebra_;
  Pipeline positions_;
  Pipeline planarity_;
  CachedArray<double> base_;
  CachedArray<Index> vertexOffsets_, vertexCorners_, cornerFace_, faceOffsets_, faceCorners_;
  Array<double> uploadedColumns_, uploadedWeights_, uploadedPrevious_;
  /// The positions written by the last two runs, alternately; each with its generation.
  Array<double> outputs_[2];
  std::shared_ptr<std::uint64_t> generations_[2];
  int next_ = 0;
  std::unique_ptr<DeviceVectors> distance_, planarityValues_;
  std::unique_ptr<DeviceScalars> measures_;
};

}  // namespace plano::vk
