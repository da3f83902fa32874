#pragma once
// Subspace ASAP/ARAP iterations on the device (compute/ReducedArap.h). The positions, the
// rest shape, the per-face covariances, rotations and targets, and the global step's
// matrices live on the device; a block of iterations is one recorded submit:
//   covariances (arap_local_step, mode 0) -> closest rotations (closest_rotations)
//   -> corner targets and face energies (mode 1) -> vertex targets g = S t (S sums a
//   vertex's corners) -> x = offset + N (G (N^T g)) -> ||B x||, ||x||.
// Per iteration three scalars come back (energy, ||B x||^2, ||x||^2), once per block. The
// positions before each global step are kept on the device (one copy per iteration of the
// block), so the host's stopping test can take any of them without re-running.
#include <memory>
#include <vector>

#include "compute/ReducedArap.h"
#include "compute/vulkan/VulkanLinearAlgebra.h"

namespace plano::vk {

class ReducedArapKernels final : public compute::ReducedArapKernels {
 public:
  /// Iterations per submit: the most the stopping test can waste is one block less one.
  static constexpr int kBlock = 8;

  /// Upload the problem. Throws Error(Device) when a buffer exceeds the device.
  ReducedArapKernels(Context& context, const compute::ReducedArapProblem& problem);
  ~ReducedArapKernels() override;

  int preferredBlock() const override { return kBlock; }
  void start(const Positions& X) override;
  std::vector<compute::ReducedArapMeasures> iterate(int count) override;
  void positions(int index, Positions& X) override;

 private:
  Sequence& block(int count);

  Context& context_;
  std::uint32_t vertices_;
  std::uint32_t faces_;
  bool asap_;
  LinearAlgebra algebra_;
  Pipeline localStep_;
  Pipeline rotations_;
  Array<std::int32_t> faceOffsets_;
  Array<std::int32_t> faceIndices_;
  DeviceVectors source_;         ///< Y, 3 #V.
  DeviceVectors x_;              ///< The current positions, 3 #V.
  std::vector<DeviceVectors> before_;  ///< x before each global step of a block.
  DeviceVectors covariances_;    ///< 9 per face.
  DeviceVectors rotationMatrices_;
  DeviceVectors singular_;       ///< 3 per face.
  DeviceVectors cornerTargets_;  ///< 3 per corner.
  DeviceVectors faceEnergy_;
  DeviceVectors ones_;           ///< #F ones: the energy is faceEnergy . ones.
  DeviceVectors vertexTargets_;  ///< g, 3 #V.
  DeviceVectors coefficients_;   ///< N^T g, d.
  DeviceVectors gained_;         ///< G N^T g, d.
  DeviceVectors offset_;
  DeviceVectors Bx_;
  DeviceCsrMatrix gather_;       ///< S: 3 #V x 3 #corners.
  DeviceCsrMatrix basis_;        ///< N.
  DeviceCsrMatrix basisTransposed_;
  DeviceCsrMatrix gain_;         ///< G (dense, as CSR).
  DeviceCsrMatrix constraints_;
  DeviceScalars measures_;       ///< 3 per iteration of a block.
  std::unique_ptr<DescriptorSet> localSet_, rotationSet_;  ///< Built once: every block binds the same buffers.
  std::vector<std::unique_ptr<Sequence>> blocks_;  ///< Recorded blocks by iteration count.
  int lastCount_ = 0;
};

}  // namespace plano::vk
