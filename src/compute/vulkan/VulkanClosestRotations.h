#pragma once
// Batched closest rotations (orthogonal Procrustes, projective-maps paper App. A) on the
// device: shaders/closest_rotations.comp, one-sided Jacobi SVD per 3x3 matrix, fp64.
#include <Eigen/Core>
#include <span>

#include "compute/vulkan/VulkanSequence.h"

namespace plano::vk {

class ClosestRotationsKernel {
 public:
  explicit ClosestRotationsKernel(Context& context);

  /// For each matrix M = U S V^T: rotations[i] = U diag(1, 1, d) V^T, d = det(U V^T), and
  /// singularValues[i] = (s1, s2, d s3). All spans have the same length (throws
  /// Error(Usage) otherwise). Large batches run in chunks that fit one storage binding.
  void run(std::span<const Eigen::Matrix3d> matrices, std::span<Eigen::Matrix3d> rotations,
           std::span<Eigen::Vector3d> singularValues);

 private:
  Context& context_;
  Pipeline pipeline_;
  // Reused across calls (grow-only).
  Array<double> input_, output_, singular_;
};

}  // namespace plano::vk
