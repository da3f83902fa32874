#include "compute/vulkan/VulkanSmoothedTransfer.h"

#include <algorithm>
#include <set>
#include <string>

#include "compute/BlockMultigrid.h"
#include "compute/SparsePattern.h"
#include "compute/vulkan/LinearAlgebraPushConstants.h"
#include "core/Error.h"

namespace plano::vk {
namespace {

struct ProlongationPush {  // mg_smoothed_prolongation
  std::uint32_t rows, b;
  double maxDamping, spectralBound;
};
struct ProductPush {  // la_block_product_transposed
  std::uint32_t blockCount, b;
};

/// A with sorted column indices, compressed (the merges of la_block_product_transposed
/// and the lookups of storedEntryIndex need them sorted).
compute::SparseMatrix sortedPattern(const compute::SparseMatrix& A) {
  const Eigen::SparseMatrix<double, Eigen::ColMajor, int> columnMajor = A;
  compute::SparseMatrix sorted = columnMajor;
  sorted.makeCompressed();
  return sorted;
}

/// P's block-complete pattern: block row i holds every column of each coarse
/// block that is the aggregate of a block K couples to block i.
compute::SparseMatrix prolongationPattern(const compute::SparseMatrix& fine, const std::vector<Index>& aggregate,
                                          Index coarseBlocks, Index b) {
  const Index blocks = fine.rows() / b;
  std::vector<Eigen::Triplet<double, int>> entries;
  for (Index i = 0; i < blocks; ++i) {
    std::set<Index> coarse;
    for (Index r = i * b; r < (i + 1) * b; ++r) {
      for (compute::SparseMatrix::InnerIterator it(fine, r); it; ++it) coarse.insert(aggregate[it.col() / b]);
    }
    coarse.insert(aggregate[i]);  // Z's own entry, should K store no diagonal block
    for (Index r = i * b; r < (i + 1) * b; ++r) {
      for (Index J : coarse) {
        for (Index k = 0; k < b; ++k) entries.emplace_back(static_cast<int>(r), static_cast<int>(J * b + k), 1.0);
      }
    }
  }
  compute::SparseMatrix pattern(fine.rows(), coarseBlocks * b);
  pattern.setFromTriplets(entries.begin(), entries.end());
  pattern.makeCompressed();
  return pattern;
}

/// A's pattern with every b x b block it touches stored whole (values 1).
compute::SparseMatrix blockComplete(const compute::SparseMatrix& A, Index b) {
  std::vector<Eigen::Triplet<double, int>> entries;
  for (Index r = 0; r < A.rows(); ++r) {
    for (compute::SparseMatrix::InnerIterator it(A, r); it; ++it) {
      const Index I = r / b, J = it.col() / b;
      for (Index q = 0; q < b; ++q) {
        for (Index k = 0; k < b; ++k) {
          entries.emplace_back(static_cast<int>(I * b + q), static_cast<int>(J * b + k), 1.0);
        }
      }
    }
  }
  compute::SparseMatrix pattern(A.rows(), A.cols());
  pattern.setFromTriplets(entries.begin(), entries.end(), [](double, double) { return 1.0; });
  pattern.makeCompressed();
  return pattern;
}

/// For every block of the block-complete C: its block row and the position of its first
/// entry among C's stored entries (la_block_product_transposed's list of work).
std::vector<std::int32_t> blockList(const compute::SparseMatrix& C, Index b) {
  std::vector<std::int32_t> list;
  for (Index I = 0; I < C.rows() / b; ++I) {
    for (Index e = C.outerIndexPtr()[I * b]; e < C.outerIndexPtr()[I * b + 1]; e += b) {
      list.push_back(static_cast<std::int32_t>(I));
      list.push_back(static_cast<std::int32_t>(e));
    }
  }
  return list;
}

std::unique_ptr<Array<std::int32_t>> uploadedList(Context& context, const std::vector<std::int32_t>& list) {
  auto array = std::make_unique<Array<std::int32_t>>(context, std::max<std::size_t>(list.size(), 2), MemoryClass::Device,
                                                     "multigrid product blocks");
  if (!list.empty()) array->upload(list);
  return array;
}

/// For each stored entry (r, c) of K, the entry (r, b aggregate[c / b] + c % b)
/// of P's pattern it adds into: (K Z)'s values gathered onto that pattern.
std::vector<std::int32_t> kzTargets(const compute::SparseMatrix& fine, const compute::SparseMatrix& pattern,
                                    const std::vector<Index>& aggregate, Index b) {
  std::vector<std::int32_t> targets = compute::entryTargets(
      fine, pattern, [](Index r) { return r; }, [&](Index c) { return b * aggregate[c / b] + c % b; });
  if (std::find(targets.begin(), targets.end(), -1) != targets.end()) {
    throwDevice("Vulkan smoothed multigrid: an entry of K Z outside P's pattern");
  }
  return targets;
}

}  // namespace

SmoothedTransfer::SmoothedTransfer(Context& context, LinearAlgebra& algebra, const compute::SparseMatrix& fine,
                                   const std::vector<Index>& aggregate, Index coarseBlocks, std::uint32_t b)
    : context_(context),
      algebra_(algebra),
      block_(b),
      fineEntries_(elementCount(fine.nonZeros(), "a multigrid level's entries")),
      prolongation_(context, "mg_smoothed_prolongation", 8, sizeof(ProlongationPush)),
      productTransposed_(context, "la_block_product_transposed", 10, sizeof(ProductPush)) {
  if (fine.rows() != fine.cols() || fine.rows() % b != 0 || static_cast<Index>(aggregate.size()) * b != fine.rows()) {
    throwUsage("smoothed multigrid: a " + std::to_string(fine.rows()) + "-row level for " +
               std::to_string(aggregate.size()) + " aggregates of " + std::to_string(b) + " rows");
  }
  const compute::SparseMatrix finePattern = compute::ones(fine);
  // K's values arrive in this order, and the merges need its columns sorted.
  for (Index r = 0; r < finePattern.rows(); ++r) {
    for (Index e = finePattern.outerIndexPtr()[r] + 1; e < finePattern.outerIndexPtr()[r + 1]; ++e) {
      if (finePattern.innerIndexPtr()[e - 1] >= finePattern.innerIndexPtr()[e]) {
        throwUsage("smoothed multigrid: K's pattern has unsorted columns");
      }
    }
  }
  const compute::SparseMatrix P = prolongationPattern(finePattern, aggregate, coarseBlocks, b);
  const compute::SparseMatrix Pt = sortedPattern(compute::SparseMatrix(P.transpose()));
  // The products read K on its block-complete pattern: a copy of K's values there where
  // K's own pattern is not (level 0's may leave out entries of a block; coarse ones never do).
  const compute::SparseMatrix Kb = blockComplete(finePattern, b);
  if (Kb.nonZeros() != finePattern.nonZeros()) {
    Kb_ = std::make_unique<DeviceCsrMatrix>(context, Kb);
    const auto same = [](Index i) { return i; };
    toKb_ = std::make_unique<DeviceGather>(context, compute::entryTargets(finePattern, Kb, same, same),
                                           elementCount(Kb.nonZeros(), "a multigrid level's entries"),
                                           "multigrid block-complete K");
  }
  const compute::SparseMatrix W = sortedPattern(compute::SparseMatrix(Pt * Kb));
  coarsePattern_ = compute::ones(sortedPattern(compute::SparseMatrix(W * P)));
  P_ = std::make_unique<DeviceCsrMatrix>(context, P);
  Pt_ = std::make_unique<DeviceCsrMatrix>(context, Pt);
  W_ = std::make_unique<DeviceCsrMatrix>(context, W);
  wBlocks_ = uploadedList(context, blockList(W, b));
  coarseBlocks_ = uploadedList(context, blockList(coarsePattern_, b));
  toKZ_ = std::make_unique<DeviceGather>(context, kzTargets(finePattern, P, aggregate, b),
                                         elementCount(P.nonZeros(), "a prolongation's entries"), "multigrid K Z");
  transpose_ =
      std::make_unique<DeviceGather>(context, compute::transposeTargets(P),
                                     elementCount(P.nonZeros(), "a prolongation's entries"), "multigrid P^T values");
  kz_ = std::make_unique<Array<double>>(context, static_cast<std::size_t>(P.nonZeros()), MemoryClass::Device,
                                        "multigrid K Z values");
  smoother_ = std::make_unique<Array<double>>(context, static_cast<std::size_t>(fine.rows()) * b, MemoryClass::Device,
                                              "multigrid smoother blocks");
  std::vector<std::int32_t> parents(aggregate.begin(), aggregate.end());
  aggregates_ =
      std::make_unique<Array<std::int32_t>>(context, parents.size(), MemoryClass::Device, "multigrid aggregates");
  aggregates_->upload(parents);
  const std::uint32_t rows = elementCount(fine.rows(), "a multigrid level's rows");
  Eigen::MatrixXd start(rows, 1);
  for (std::uint32_t i = 0; i < rows; ++i) start(i, 0) = 1.0 + static_cast<double>(i % 7) / 7.0;
  start_ = std::make_unique<DeviceVectors>(context, rows, 1, "multigrid power iteration start");
  start_->upload(start);
  even_ = std::make_unique<DeviceVectors>(context, rows, 1, "multigrid power iterate");
  odd_ = std::make_unique<DeviceVectors>(context, rows, 1, "multigrid power iterate");
  product_ = std::make_unique<DeviceVectors>(context, rows, 1, "multigrid power iteration product");
  norms_ = std::make_unique<DeviceScalars>(context, 2, 1, rows);
}

SmoothedTransfer::~SmoothedTransfer() = default;

void SmoothedTransfer::record(Sequence& sequence, const DeviceCsrMatrix& K, const Array<double>& inverses,
                              DeviceCsrMatrix& coarse) {
  if (K.rows() != P_->rows() || K.values().count() != fineEntries_ || coarse.rows() != P_->cols()) {
    throwUsage("smoothed multigrid: a level matrix of another pattern");
  }
  // lambda_max(D^-1 K): v_k = (D^-1 K)^k v_0; norms_ gets ||v_k-1||^2 (slot 0),
  // ||v_k||^2 (slot 1).
  const DeviceVectors* v = start_.get();
  for (int k = 1; k <= kPowerIterations; ++k) {
    DeviceVectors& next = k % 2 == 0 ? *even_ : *odd_;
    algebra_.spmv(sequence, K, *v, *product_);
    algebra_.applyBlockDiagonal(sequence, inverses, block_, *product_, next);
    if (k == kPowerIterations) algebra_.dot(sequence, *v, *v, *norms_, 0);
    v = &next;
  }
  algebra_.dot(sequence, *v, *v, *norms_, 1);
  algebra_.gatherSum(sequence, *toKZ_, K.values(), *kz_);
  const std::uint32_t rows = P_->rows();
  const compute::BlockMultigridSettings defaults;
  sequence.dispatch(prolongation_,
                    {P_->rowOffsets(), P_->columns(), *kz_, inverses, *aggregates_, norms_->values(), P_->values(),
                     *smoother_},
                    ProlongationPush{rows, block_, defaults.smootherDamping, defaults.smootherSpectralBound},
                    groupsFor(context_, rows));
  sequence.barrier();
  algebra_.gatherSum(sequence, *transpose_, P_->values(), Pt_->values());
  const DeviceCsrMatrix* Kb = &K;
  if (toKb_) {
    algebra_.gatherSum(sequence, *toKb_, K.values(), Kb_->values());
    Kb = Kb_.get();
  }
  recordProduct(sequence, *Pt_, *Kb, *W_, *wBlocks_);         // W = P^T K^T = P^T K
  recordProduct(sequence, *Pt_, *W_, coarse, *coarseBlocks_);  // P^T W^T = P^T K P
}

void SmoothedTransfer::recordProduct(Sequence& sequence, const DeviceCsrMatrix& A, const DeviceCsrMatrix& B,
                                     DeviceCsrMatrix& C, const Array<std::int32_t>& blocks) {
  if (C.values().count() % (block_ * block_) != 0) throwUsage("smoothed multigrid: a product that is not block-complete");
  const auto blockCount = static_cast<std::uint32_t>(C.values().count() / (block_ * block_));
  sequence.dispatch(productTransposed_,
                    {A.rowOffsets(), A.columns(), A.values(), B.rowOffsets(), B.columns(), B.values(), C.rowOffsets(),
                     C.columns(), C.values(), blocks},
                    ProductPush{blockCount, block_}, groupsFor(context_, blockCount));
  sequence.barrier();
}

}  // namespace plano::vk
