#pragma once
// One level's smoothed-aggregation transfer on the device: the prolongation
// P = (I - omega D^-1 K) Z of compute::BlockMultigrid (BlockMultigridSettings::
// smoothProlongation), its transpose, the level's damped smoother and the coarse matrix
// P^T K P, formed from K's values on the device whenever K changes, so that a rho update
// stays device work.
//
// Why not the K0_l + rho K1_l split of the plain cycle: P depends on K, so the coarse
// matrices are no longer linear in rho; they are recomputed at each rho update instead,
// a few products over fixed patterns, far less work than the PCG iterations between two
// updates.
//
// Patterns are fixed at construction from K's pattern and the aggregates: P's is
// block-complete (the b rows of a block store the same columns: every coarse block that
// is a neighbouring block's aggregate), and the products' patterns come from products of
// all-ones patterns. The steps of record():
//   lambda:  kPowerIterations power iterations v <- D^-1 K v from compute::BlockMultigrid's
//            start vector, unnormalised (the ratio of the last two norms is the estimate;
//            the growth stays far within double range), then the last two squared norms;
//   KZ:      a gather of K's values onto P's pattern (each entry of K adds into one);
//   P:       shaders/mg_smoothed_prolongation.comp, with the level's damped smoother
//            (BlockMultigridSettings::smootherSpectralBound); P^T's values by a gather;
//   P^T K P: W = P^T K, then P^T W^T, each shaders/la_block_product_transposed.comp over
//            4x4 blocks (K is symmetric; all patterns block-complete, level 0's K copied
//            onto its block-complete pattern where it is not).
#include <memory>
#include <vector>

#include "compute/Backend.h"
#include "compute/vulkan/VulkanLinearAlgebra.h"

namespace plano::vk {

class SmoothedTransfer {
 public:
  /// Power iterations of the omega estimate (compute::BlockMultigrid's count: both
  /// backends then form the same P).
  static constexpr int kPowerIterations = 30;

  /// The transfer from a level of pattern `fine` (K's: compressed, sorted, structurally
  /// symmetric; values ignored) to the level of `aggregate`'s coarseBlocks blocks of b rows.
  /// `algebra` is kept by reference.
  SmoothedTransfer(Context& context, LinearAlgebra& algebra, const compute::SparseMatrix& fine,
                   const std::vector<Index>& aggregate, Index coarseBlocks, std::uint32_t b);
  ~SmoothedTransfer();
  SmoothedTransfer(const SmoothedTransfer&) = delete;
  SmoothedTransfer& operator=(const SmoothedTransfer&) = delete;

  /// The coarse matrix's pattern (values 1), for the coarse level's DeviceCsrMatrix.
  const compute::SparseMatrix& coarsePattern() const { return coarsePattern_; }
  /// Record P and the smoother from K (on the fine pattern) and its undamped block-Jacobi
  /// `inverses`, then coarse's values = P^T K P (coarse on coarsePattern()).
  void record(Sequence& sequence, const DeviceCsrMatrix& K, const Array<double>& inverses, DeviceCsrMatrix& coarse);

  const DeviceCsrMatrix& P() const { return *P_; }
  const DeviceCsrMatrix& transposedP() const { return *Pt_; }
  /// The fine level's block-Jacobi smoother: its inverses, damped (formed by record()).
  const Array<double>& smoother() const { return *smoother_; }

 private:
  /// C = A B^T over C's `blocks` (blockList), all three block-complete.
  void recordProduct(Sequence& sequence, const DeviceCsrMatrix& A, const DeviceCsrMatrix& B, DeviceCsrMatrix& C,
                     const Array<std::int32_t>& blocks);

  Context& context_;
  LinearAlgebra& algebra_;
  std::uint32_t block_;
  std::uint32_t fineEntries_;
  compute::SparseMatrix coarsePattern_;
  std::unique_ptr<DeviceCsrMatrix> P_, Pt_, W_;
  std::unique_ptr<DeviceCsrMatrix> Kb_;  ///< K on its block-complete pattern, where K's own is not.
  std::unique_ptr<DeviceGather> toKZ_, transpose_, toKb_;
  std::unique_ptr<Array<std::int32_t>> wBlocks_, coarseBlocks_;
  std::unique_ptr<Array<double>> kz_, smoother_;
  std::unique_ptr<Array<std::int32_t>> aggregates_;
  std::unique_ptr<DeviceVectors> start_, even_, odd_, product_;
  std::unique_ptr<DeviceScalars> norms_;
  Pipeline prolongation_, productTransposed_;
};

}  // namespace plano::vk
