#pragma once
// The reduced operator R = N^T (S (x) I_k) N of a linear space (compute/ReducedOperator.h)
// on the device: N uploaded once in blocks of columns, S once as CSR; per block J of
// columns, W = (S (x) I_k) N_J (shaders/reduced_spmm.comp), then every block R[I, J] =
// N_I^T W (shaders/reduced_gemm.comp, shared-memory tiles, the long dimension split into
// chunks whose partial sums shaders/reduced_sum_partials.comp adds), all in one submit.
// Only R (d x d) comes back. Blocks keep every buffer within the device's storage-buffer
// range (and a cap that keeps one allocation modest), so a basis of any size that fits the
// device's memory runs.
#include <Eigen/Core>
#include <cstddef>

#include "compute/Backend.h"
#include "compute/vulkan/VulkanPipeline.h"

namespace plano::vk {

class ReducedOperatorKernel {
 public:
  /// Largest buffer of basis columns by default (the device's storage-buffer range may be lower).
  static constexpr std::size_t kDefaultBlockBytes = std::size_t{1} << 30;

  /// Builds the pipelines. `blockBytes` > 0 caps each block of columns at that many bytes
  /// (tests use a small cap to run many blocks).
  explicit ReducedOperatorKernel(Context& context, std::size_t blockBytes = 0);

  /// R = N^T (S (x) I_k) N, k = coordinates. Throws Error(Usage) for mismatched sizes and
  /// Error(Device) when one column of N or R itself exceeds the device's storage-buffer
  /// range, or the basis does not fit the device's memory.
  Eigen::MatrixXd run(const compute::SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates);

 private:
  Context& context_;
  std::size_t blockBytes_;
  Pipeline spmm_;
  Pipeline gemm_;
  Pipeline sumPartials_;
};

}  // namespace plano::vk
