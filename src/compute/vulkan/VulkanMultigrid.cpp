#include "compute/vulkan/VulkanMultigrid.h"

#include <algorithm>
#include <string>
#include <thread>

#include "compute/SparsePattern.h"
#include "compute/vulkan/LinearAlgebraPushConstants.h"
#include "core/Error.h"

namespace plano::vk {
namespace {

struct TransferPush {  // mg_residual_restrict, mg_prolong
  std::uint32_t fineRows, coarseRows, m, b;
};
struct CoarsestAssemblePush {  // mg_coarsest_assemble
  std::uint32_t rows, pad;
  double rho;
};
struct CoarsestInvertPush {  // mg_coarsest_invert
  std::uint32_t rows, step, failureCode, unused;
};

/// Workgroups of one elimination step of the coarsest level's inversion (rows of the upper
/// triangle dealt out among them; shaders/mg_coarsest_invert.comp). A CPU device (lavapipe)
/// runs a workgroup on one of the host's cores, and each workgroup loads the pivot's whole
/// column: one per core. A GPU gets about 16 entries per invocation. One step is within
/// llvmpipe's loop limit (kCpuLoopBackEdges) even in one workgroup: its lanes loop about
/// rows^2 / (2 lanes) + 2 rows times, 10 240 for kMaxCoarsestRows.
std::uint32_t inversionGroups(const Context& context, std::uint32_t rows) {
  std::uint64_t groups = 1;
  if (isCpuDevice(context)) {
    groups = std::max(1u, std::thread::hardware_concurrency());
  } else {
    const std::uint64_t entries = std::uint64_t{rows} * (rows + 1) / 2;
    groups = (entries + 16 * singleWorkgroupLanes(context) - 1) / (16 * singleWorkgroupLanes(context));
  }
  return static_cast<std::uint32_t>(std::clamp<std::uint64_t>(groups, 1, std::max<std::uint32_t>(rows, 1)));
}

/// A on `pattern` (explicit zeros where A has no entry); Error(Device) when A has an entry
/// outside it.
compute::SparseMatrix onPattern(const compute::SparseMatrix& A, const compute::SparseMatrix& pattern) {
  compute::SparseMatrix result = A + pattern * 0.0;
  result.makeCompressed();
  if (result.nonZeros() != pattern.nonZeros()) throwDevice("Vulkan multigrid: a level matrix leaves its pattern");
  return result;
}

std::span<const double> valuesOf(const compute::SparseMatrix& A) {
  return {A.valuePtr(), static_cast<std::size_t>(A.nonZeros())};
}

/// For each entry of the fine pattern, the coarse entry it adds into under the
/// aggregation's prolongation (row b i + k -> b a_i + k, columns alike).
std::vector<std::int32_t> coarseEntries(const compute::SparseMatrix& fine, const compute::SparseMatrix& coarse,
                                        const std::vector<Index>& aggregate, Index b) {
  const auto coarseIndex = [&](Index i) { return b * aggregate[i / b] + i % b; };
  std::vector<std::int32_t> targets = compute::entryTargets(fine, coarse, coarseIndex, coarseIndex);
  if (std::find(targets.begin(), targets.end(), -1) != targets.end()) {
    throwDevice("Vulkan multigrid: a fine entry has no coarse entry");
  }
  return targets;
}

}  // namespace

struct Multigrid::Level {
  std::uint32_t rows = 0;
  std::unique_ptr<DeviceCsrMatrix> K;             ///< Levels 1 .. L-2: K_l; the coarsest: K^-1 (dense).
  std::unique_ptr<Array<double>> k0, k1;          ///< Levels 1 .. L-2: values on K's pattern.
  std::unique_ptr<Array<double>> inverses;        ///< Levels 1 .. L-2: block-Jacobi inverses.
  std::unique_ptr<DeviceVectors> r, z;            ///< Levels 1 ..: restricted residual, correction.
  std::unique_ptr<DeviceVectors> t;               ///< Levels 0 .. L-2: the residual on the way up.
  std::unique_ptr<Array<std::int32_t>> aggregates, childOffsets, children;  ///< Levels 0 .. L-2.
};

/// Descriptor sets of one level's steps.
struct LevelSets {
  std::unique_ptr<DescriptorSet> smoothDown, residualDown, restrictResidual, prolongFrom, residual, smoothUp;
};

struct Multigrid::Binding::Sets {
  std::vector<LevelSets> levels;  ///< Level 0's refer to the bound operands.
  std::unique_ptr<DescriptorSet> coarsest;
};

Multigrid::Binding::Binding() : sets_(std::make_unique<Sets>()) {}
Multigrid::Binding::~Binding() = default;

Multigrid::Multigrid(Context& context, LinearAlgebra& algebra, const compute::BlockAggregation& aggregation,
                     const compute::SparseMatrix& K0, const compute::SparseMatrix& pattern,
                     bool smoothProlongation)
    : context_(context),
      algebra_(algebra),
      block_(static_cast<std::uint32_t>(aggregation.block())),
      columns_(0),
      aggregation_(aggregation),
      smoothed_(smoothProlongation && aggregation.levelCount() > 1),
      spmvAdd_(context, "la_spmv_add", 5, sizeof(SpmvPush)),
      spmv_(context, "la_spmv", 5, sizeof(SpmvPush)),
      scale_(context, "la_scale_rows", 3, sizeof(ScalePush)),
      residual_(context, "la_residual", 6, sizeof(SpmvPush)),
      scaleAdd_(context, "la_scale_rows_add", 3, sizeof(ScalePush)),
      restrictResidual_(context, "mg_residual_restrict", 8, sizeof(TransferPush)),
      prolong_(context, "mg_prolong", 3, sizeof(TransferPush)),
      assemble_(context, "admm_assemble", 5, sizeof(AssemblePush)),
      coarsestAssemble_(context, "mg_coarsest_assemble", 5, sizeof(CoarsestAssemblePush)),
      coarsestInvert_(context, "mg_coarsest_invert", 3, sizeof(CoarsestInvertPush), singleWorkgroupLanes(context)),
      noRows_(context, 1, MemoryClass::Device, "multigrid unused rows") {
  const int L = aggregation_.levelCount();
  std::vector<compute::SparseMatrix> patternLevels, k0Levels;
  if (smoothed_) {
    patternLevels.push_back(compute::ones(pattern));
    for (int l = 0; l + 1 < L; ++l) {
      transfers_.push_back(std::make_unique<SmoothedTransfer>(context, algebra, patternLevels[l],
                                                              aggregation_.aggregates(l), aggregation_.blocks(l + 1),
                                                              block_));
      patternLevels.push_back(transfers_.back()->coarsePattern());
    }
  } else {
    patternLevels = aggregation_.coarsen(compute::ones(pattern));
    k0Levels = aggregation_.coarsen(onPattern(K0, pattern));
  }
  for (int l = 0; l < L; ++l) {
    auto level = std::make_unique<Level>();
    level->rows = elementCount(patternLevels[l].rows(), "a multigrid level's rows");
    const bool coarsest = l + 1 == L;
    if (!coarsest && !smoothed_) {
      const std::vector<Index>& aggregate = aggregation_.aggregates(l);
      std::vector<std::int32_t> parents(aggregate.begin(), aggregate.end());
      std::vector<std::int32_t> offsets(aggregation_.blocks(l + 1) + 1, 0);
      for (Index a : aggregate) ++offsets[a + 1];
      for (std::size_t i = 1; i < offsets.size(); ++i) offsets[i] += offsets[i - 1];
      std::vector<std::int32_t> children(aggregate.size());
      std::vector<std::int32_t> next(offsets.begin(), offsets.end() - 1);
      for (std::size_t i = 0; i < aggregate.size(); ++i) children[next[aggregate[i]]++] = static_cast<std::int32_t>(i);
      level->aggregates = std::make_unique<Array<std::int32_t>>(context, parents.size(), MemoryClass::Device, "multigrid aggregates");
      level->aggregates->upload(parents);
      level->childOffsets = std::make_unique<Array<std::int32_t>>(context, offsets.size(), MemoryClass::Device, "multigrid aggregate offsets");
      level->childOffsets->upload(offsets);
      level->children = std::make_unique<Array<std::int32_t>>(context, children.size(), MemoryClass::Device, "multigrid aggregate members");
      level->children->upload(children);
    }
    if (l > 0 && !coarsest && smoothed_) {
      level->K = std::make_unique<DeviceCsrMatrix>(context, patternLevels[l]);  // values from setRho
    } else if (l > 0 && !coarsest) {
      const compute::SparseMatrix values = onPattern(k0Levels[l], patternLevels[l]);
      level->K = std::make_unique<DeviceCsrMatrix>(context, values);
      level->k0 = std::make_unique<Array<double>>(context, values.nonZeros(), MemoryClass::Device, "multigrid K0 values");
      level->k0->upload(valuesOf(values));
      level->k1 = std::make_unique<Array<double>>(context, values.nonZeros(), MemoryClass::Device, "multigrid K1 values");
    }
    if (l > 0 && !coarsest) {
      level->inverses = std::make_unique<Array<double>>(context, static_cast<std::size_t>(level->rows) * block_,
                                                        MemoryClass::Device, "multigrid block inverses");
    }
    if (coarsest) {
      if (level->rows > kMaxCoarsestRows) {
        throwDevice("Vulkan multigrid: a coarsest level of " + std::to_string(level->rows) + " rows (at most " +
                    std::to_string(kMaxCoarsestRows) + ")");
      }
      const compute::SparseMatrix dense = Eigen::MatrixXd::Ones(level->rows, level->rows).sparseView();
      compute::SparseMatrix full = dense;
      full.makeCompressed();
      level->K = std::make_unique<DeviceCsrMatrix>(context, full);
      // Smoothed: the coarsest K itself, written by the last transfer (its K1 part stays 0).
      coarsestK0_ = std::make_unique<DeviceCsrMatrix>(
          context, smoothed_ ? patternLevels[l] : onPattern(k0Levels[l], patternLevels[l]));
      sweepSaved_ = std::make_unique<Array<double>>(context, 2 * (std::size_t{level->rows} + 1), MemoryClass::Device,
                                                    "multigrid inversion's saved columns");
    }
    patterns_.push_back(patternLevels[l]);
    levels_.push_back(std::move(level));
  }
  for (int l = 0; l + 1 < L && !smoothed_; ++l) {
    const std::vector<std::int32_t> targets =
        coarseEntries(patterns_[l], patterns_[l + 1], aggregation_.aggregates(l), block_);
    coarsenings_.push_back(std::make_unique<DeviceGather>(
        context, targets, elementCount(patterns_[l + 1].nonZeros(), "a multigrid level's entries"),
        "multigrid coarsening"));
  }
  coarsestK1Values_ = std::make_unique<Array<double>>(context, static_cast<std::size_t>(patterns_.back().nonZeros()),
                                                      MemoryClass::Device, "multigrid coarsest K1 values");
  if (smoothed_) {
    const std::vector<double> zeros(coarsestK1Values_->count(), 0.0);
    coarsestK1Values_->upload(zeros);
  }
}

Multigrid::~Multigrid() = default;

const Array<double>* Multigrid::wholeInverse() const {
  return levelCount() == 1 ? &levels_.front()->K->values() : nullptr;
}

void Multigrid::setK1(Sequence& sequence, const Array<double>& k1) {
  k1Set_ = true;
  if (smoothed_) return;  // coarse levels come from K itself (setRho)
  const int L = levelCount();
  if (L == 1) {
    sequence.copy(k1, *coarsestK1Values_, coarsestK1Values_->count() * sizeof(double));
    sequence.barrier();
    return;
  }
  for (int l = 0; l + 1 < L; ++l) {
    const Array<double>& fine = l == 0 ? k1 : *levels_[l]->k1;
    Array<double>& coarse = l + 2 == L ? *coarsestK1Values_ : *levels_[l + 1]->k1;
    algebra_.gatherSum(sequence, *coarsenings_[l], fine, coarse);
  }
}

void Multigrid::setK1(const compute::SparseMatrix& K1) {
  const compute::SparseMatrix values = onPattern(K1, patterns_.front());
  Array<double> k1(context_, static_cast<std::size_t>(values.nonZeros()), MemoryClass::Device, "multigrid K1 values");
  k1.upload(valuesOf(values));
  Sequence sequence(context_);
  sequence.begin();
  setK1(sequence, k1);
  sequence.end();
  sequence.run();
}

void Multigrid::setRho(Sequence& sequence, double rho, const DeviceCsrMatrix& K, const Array<double>& inverses,
                       Array<std::uint32_t>& failure) {
  if (!smoothed_) {
    setRho(sequence, rho, failure);
    return;
  }
  const int L = levelCount();
  for (int l = 0; l + 1 < L; ++l) {
    const bool first = l == 0, lastTransfer = l + 2 == L;
    DeviceCsrMatrix& coarse = lastTransfer ? *coarsestK0_ : *levels_[l + 1]->K;
    transfers_[l]->record(sequence, first ? K : *levels_[l]->K, first ? inverses : *levels_[l]->inverses, coarse);
    if (!lastTransfer) algebra_.invertDiagonalBlocks(sequence, coarse, block_, *levels_[l + 1]->inverses, failure);
  }
  recordCoarsestInverse(sequence, 0.0, failure);
}

void Multigrid::setRho(Sequence& sequence, double rho, Array<std::uint32_t>& failure) {
  if (smoothed_) throwUsage("smoothed multigrid: setRho needs level 0's K and block inverses");
  if (!k1Set_) throwUsage("multigrid: setRho before setK1");
  for (int l = 1; l + 1 < levelCount(); ++l) {
    Level& level = *levels_[l];
    const auto nonZeros = static_cast<std::uint32_t>(level.k0->count());
    sequence.dispatch(assemble_, {*level.k0, *level.k1, level.K->values(), noRows_, noRows_},
                      AssemblePush{nonZeros, 0, rho}, groupsFor(context_, nonZeros));
    sequence.barrier();
    algebra_.invertDiagonalBlocks(sequence, *level.K, block_, *level.inverses, failure);
  }
  recordCoarsestInverse(sequence, rho, failure);
}

void Multigrid::recordCoarsestInverse(Sequence& sequence, double rho, Array<std::uint32_t>& failure) {
  // The coarsest level: its dense inverse, in place of its dense K.
  const std::uint32_t rows = levels_.back()->rows;
  Array<double>& dense = levels_.back()->K->values();
  sequence.dispatch(coarsestAssemble_,
                    {coarsestK0_->rowOffsets(), coarsestK0_->columns(), coarsestK0_->values(), *coarsestK1Values_, dense},
                    CoarsestAssemblePush{rows, 0, rho}, groupsFor(context_, rows));
  sequence.barrier();
  // One dispatch per elimination step, then one that negates and mirrors the sweeps' -K^-1.
  const DescriptorSet& inversion = sequence.keep(coarsestInvert_, {dense, failure, *sweepSaved_});
  const std::uint32_t groups = inversionGroups(context_, rows);
  for (std::uint32_t step = 0; step <= rows; ++step) {
    sequence.dispatch(coarsestInvert_, inversion, CoarsestInvertPush{rows, step, kCoarsestFailure, 0}, groups);
    sequence.barrier();
  }
}

std::unique_ptr<Multigrid::Binding> Multigrid::bind(const DeviceCsrMatrix& K, const Array<double>& inverseBlocks,
                                                    const DeviceVectors& r, DeviceVectors& z) {
  if (r.n() != levels_.front()->rows || z.n() != r.n() || z.m() != r.m()) {
    throwUsage("multigrid: operands of " + std::to_string(r.n()) + " x " + std::to_string(r.m()) + " and " +
               std::to_string(z.n()) + " x " + std::to_string(z.m()) + " for " + std::to_string(levels_.front()->rows) +
               " rows");
  }
  const int L = levelCount();
  if (columns_ != r.m()) {  // (re)size the levels' vectors; bindings made for another count are void
    columns_ = r.m();
    for (int l = 0; l < L; ++l) {
      Level& level = *levels_[l];
      if (l > 0) {
        level.r = std::make_unique<DeviceVectors>(context_, level.rows, columns_, "multigrid residual");
        level.z = std::make_unique<DeviceVectors>(context_, level.rows, columns_, "multigrid correction");
      }
      if (l + 1 < L) level.t = std::make_unique<DeviceVectors>(context_, level.rows, columns_, "multigrid residual");
    }
  }
  std::unique_ptr<Binding> binding(new Binding());
  for (int l = 0; l + 1 < L; ++l) {
    Level& level = *levels_[l];
    Level& coarse = *levels_[l + 1];
    const DeviceCsrMatrix& matrix = l == 0 ? K : *level.K;
    // The smoothed cycle's smoother is damped (SmoothedTransfer::smoother), the plain one's not.
    const Array<double>& inverses =
        smoothed_ ? transfers_[l]->smoother() : (l == 0 ? inverseBlocks : *level.inverses);
    const Array<double>& rl = l == 0 ? r.data() : level.r->data();
    const Array<double>& zl = l == 0 ? z.data() : level.z->data();
    LevelSets sets;
    sets.smoothDown = std::make_unique<DescriptorSet>(context_, scale_, std::initializer_list<BufferRange>{inverses, rl, zl});
    if (smoothed_) {
      const DeviceCsrMatrix& P = transfers_[l]->P();
      const DeviceCsrMatrix& Pt = transfers_[l]->transposedP();
      sets.residualDown = std::make_unique<DescriptorSet>(
          context_, residual_,
          std::initializer_list<BufferRange>{matrix.rowOffsets(), matrix.columns(), matrix.values(), zl, rl,
                                             level.t->data()});
      sets.restrictResidual = std::make_unique<DescriptorSet>(
          context_, spmv_,
          std::initializer_list<BufferRange>{Pt.rowOffsets(), Pt.columns(), Pt.values(), level.t->data(),
                                             coarse.r->data()});
      sets.prolongFrom = std::make_unique<DescriptorSet>(
          context_, spmvAdd_,
          std::initializer_list<BufferRange>{P.rowOffsets(), P.columns(), P.values(), coarse.z->data(), zl});
    } else {
      sets.restrictResidual = std::make_unique<DescriptorSet>(
          context_, restrictResidual_,
          std::initializer_list<BufferRange>{matrix.rowOffsets(), matrix.columns(), matrix.values(), zl, rl,
                                             *level.childOffsets, *level.children, coarse.r->data()});
      sets.prolongFrom = std::make_unique<DescriptorSet>(
          context_, prolong_, std::initializer_list<BufferRange>{*level.aggregates, coarse.z->data(), zl});
    }
    sets.residual = std::make_unique<DescriptorSet>(
        context_, residual_,
        std::initializer_list<BufferRange>{matrix.rowOffsets(), matrix.columns(), matrix.values(), zl, rl,
                                           level.t->data()});
    sets.smoothUp = std::make_unique<DescriptorSet>(context_, scaleAdd_,
                                                    std::initializer_list<BufferRange>{inverses, level.t->data(), zl});
    binding->sets_->levels.push_back(std::move(sets));
  }
  const Level& last = *levels_.back();
  const Array<double>& rc = L == 1 ? r.data() : last.r->data();
  const Array<double>& zc = L == 1 ? z.data() : last.z->data();
  binding->sets_->coarsest = std::make_unique<DescriptorSet>(
      context_, spmv_, std::initializer_list<BufferRange>{last.K->rowOffsets(), last.K->columns(), last.K->values(), rc, zc});
  return binding;
}

void Multigrid::record(Sequence& sequence, const Binding& binding, const Buffer* arguments, std::size_t triple) {
  const std::uint32_t k = columns_;
  if (k == 0) throwUsage("multigrid: record before bind");
  // Every kernel loops grid-stride over its entries, or its rows for the products (which take
  // every column of a row, reading K's row once), in one row of workgroups.
  auto run = [&](const Pipeline& pipeline, const DescriptorSet& set, const auto& push, std::uint32_t count) {
    if (arguments) {
      sequence.dispatchIndirect(pipeline, set, push, *arguments, triple);
    } else {
      sequence.dispatch(pipeline, set, push, sweepGroupsFor(context_, count));
    }
    sequence.barrier();
  };
  const int L = levelCount();
  for (int l = 0; l + 1 < L; ++l) {
    const LevelSets& sets = binding.sets_->levels[l];
    const std::uint32_t n = levels_[l]->rows, nc = levels_[l + 1]->rows;
    run(scale_, *sets.smoothDown, ScalePush{n, k, block_}, n * k);  // z = S r
    if (smoothed_) {
      run(residual_, *sets.residualDown, SpmvPush{n, n, k}, n);    // t = r - K z
      run(spmv_, *sets.restrictResidual, SpmvPush{nc, n, k}, nc);  // r_c = P^T t
    } else {
      run(restrictResidual_, *sets.restrictResidual, TransferPush{n, nc, k, block_}, nc);  // r_c = Z^T (r - K z)
    }
  }
  const std::uint32_t nc = levels_.back()->rows;
  run(spmv_, *binding.sets_->coarsest, SpmvPush{nc, nc, k}, nc);  // z_c = K_c^-1 r_c
  for (int l = L - 2; l >= 0; --l) {
    const LevelSets& sets = binding.sets_->levels[l];
    const std::uint32_t n = levels_[l]->rows, coarse = levels_[l + 1]->rows;
    if (smoothed_) {
      run(spmvAdd_, *sets.prolongFrom, SpmvPush{n, coarse, k}, n);  // z += P z_c
    } else {
      run(prolong_, *sets.prolongFrom, TransferPush{n, coarse, k, block_}, n * k);  // z += Z z_c
    }
    run(residual_, *sets.residual, SpmvPush{n, n, k}, n);                         // t = r - K z
    run(scaleAdd_, *sets.smoothUp, ScalePush{n, k, block_}, n * k);               // z += S t
  }
}

}  // namespace plano::vk
