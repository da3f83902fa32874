#include "compute/vulkan/VulkanAdmm.h"

#include <algorithm>
#include <limits>
#include <string>
#include <utility>

#include "compute/SparsePattern.h"
#include "compute/vulkan/LinearAlgebraPushConstants.h"
#include "compute/vulkan/PcgPushConstants.h"
#include "compute/vulkan/VulkanAdmmWorkspace.h"
#include "core/Cancellation.h"
#include "core/Error.h"

namespace plano::vk {

using namespace admm;

namespace {

std::uint32_t blockSize(int block, std::uint32_t n) {
  if (block < 1 || block > 4 || n % static_cast<std::uint32_t>(block) != 0) {
    throwUsage("ADMM: preconditioner blocks of " + std::to_string(block) + " rows for " + std::to_string(n) +
               " unknowns (need 1 to 4 rows dividing the unknowns)");
  }
  return static_cast<std::uint32_t>(block);
}

/// P + sigma I with explicit zeros wherever C^T C has an entry: the union pattern, so that
/// K0 and K1 share one index layout and K = K0 + rho K1 is an entrywise sum.
compute::SparseMatrix unionPatternK0(const compute::SparseMatrix& P, const compute::SparseMatrix& C, double sigma) {
  if (P.rows() != P.cols() || C.cols() != P.rows()) {
    throwUsage("ADMM: P is " + std::to_string(P.rows()) + "x" + std::to_string(P.cols()) + " and C is " +
               std::to_string(C.rows()) + "x" + std::to_string(C.cols()) + " (need n x n and m x n)");
  }
  compute::SparseMatrix I(P.rows(), P.rows());
  I.setIdentity();
  const compute::SparseMatrix CtC = C.transpose() * C;
  compute::SparseMatrix K0 = P + I * sigma + CtC * 0.0;
  K0.makeCompressed();
  return K0;
}

/// The terms of K1 = C^T D C on K's pattern: entry (i, j) of K sums C(r, i) D_r C(r, j)
/// over the rows r of C that have both columns; a and b index C's stored values, listed per
/// entry of K (CSR), and entryRows gives each stored value of C its row.
struct K1Terms {
  std::vector<std::int32_t> offsets, a, b, entryRows;
};

K1Terms k1Terms(const compute::SparseMatrix& C, const compute::SparseMatrix& K) {
  K1Terms terms;
  const std::int32_t* outer = C.outerIndexPtr();
  const std::int32_t* inner = C.innerIndexPtr();
  // Count per entry of K, then place (two passes: the term list is the largest array here).
  std::vector<std::int64_t> offsets(static_cast<std::size_t>(K.nonZeros()) + 1, 0);
  auto forEachTerm = [&](auto&& visit) {
    for (Eigen::Index r = 0; r < C.rows(); ++r) {
      for (std::int32_t p = outer[r]; p < outer[r + 1]; ++p) {
        for (std::int32_t q = outer[r]; q < outer[r + 1]; ++q) {
          const std::int32_t e = compute::storedEntryIndex(K, inner[p], inner[q]);
          if (e < 0) throwDevice("Vulkan ADMM: K's pattern lacks an entry of C^T C");
          visit(e, p, q);
        }
      }
    }
  };
  forEachTerm([&](std::int32_t e, std::int32_t, std::int32_t) { ++offsets[static_cast<std::size_t>(e) + 1]; });
  for (std::size_t e = 1; e < offsets.size(); ++e) offsets[e] += offsets[e - 1];
  elementCount(offsets.back(), "the terms of C^T C");
  terms.a.resize(static_cast<std::size_t>(offsets.back()));
  terms.b.resize(terms.a.size());
  std::vector<std::int64_t> next(offsets.begin(), offsets.end() - 1);
  forEachTerm([&](std::int32_t e, std::int32_t p, std::int32_t q) {
    const auto t = static_cast<std::size_t>(next[static_cast<std::size_t>(e)]++);
    terms.a[t] = p;
    terms.b[t] = q;
  });
  terms.offsets.assign(offsets.begin(), offsets.end());
  terms.entryRows.resize(static_cast<std::size_t>(C.nonZeros()));
  for (Eigen::Index r = 0; r < C.rows(); ++r) {
    for (std::int32_t p = outer[r]; p < outer[r + 1]; ++p) {
      terms.entryRows[static_cast<std::size_t>(p)] = static_cast<std::int32_t>(r);
    }
  }
  return terms;
}

/// Upload `values` to `device` unless `held` (what it holds) equals them: the attempts of
/// an ε schedule share q and the bounds' centre.
void uploadIfChanged(DeviceVectors& device, Eigen::MatrixXd& held, const Eigen::MatrixXd& values) {
  if (held.rows() == values.rows() && held.cols() == values.cols() && held == values) return;
  held.resize(0, 0);  // an upload that throws leaves nothing claimed
  device.upload(values);
  held = values;
}

/// A device array holding `values` (at least one element: Vulkan buffers are never empty).
Array<std::int32_t> uploaded(Context& context, const std::vector<std::int32_t>& values, const char* what) {
  Array<std::int32_t> array(context, std::max<std::size_t>(values.size(), 1), MemoryClass::Device, what);
  if (!values.empty()) array.upload(values);
  return array;
}

/// C^T C for the multigrid's aggregation: of C's values, or of its pattern (unit entries)
/// where every value is zero (C given by its pattern, its values still to come).
compute::SparseMatrix aggregationCouplings(const compute::SparseMatrix& C, const compute::SparseMatrix& Ct) {
  const bool valued = std::any_of(C.valuePtr(), C.valuePtr() + C.nonZeros(), [](double v) { return v != 0.0; });
  if (valued) return compute::SparseMatrix(Ct * C);
  const compute::SparseMatrix unit = C.unaryExpr([](double) { return 1.0; });
  return compute::SparseMatrix(compute::SparseMatrix(unit.transpose()) * unit);
}

}  // namespace

AdmmKernels::AdmmKernels(Context& context, const compute::SparseMatrix& P, const compute::SparseMatrix& C,
                         const compute::AdmmSettings& settings, AdmmRecording recording,
                         std::uint32_t unitsPerDispatch)
    : context_(context),
      settings_(settings),
      relaxation_(settings.relaxation),
      n_(elementCount(P.rows(), "the ADMM's unknown count")),
      m_(elementCount(C.rows(), "the ADMM's constraint count")),
      C_(C),
      Ct_(C.transpose()),
      K0_(unionPatternK0(P, C, settings.sigma)),
      algebra_(context),
      devP_(context, P),
      devC_(context, C_),
      devCt_(context, Ct_),
      devK_(context, K0_),
      k0Values_(context, static_cast<std::size_t>(K0_.nonZeros()), MemoryClass::Device, "ADMM K0 values"),
      k1Values_(context, static_cast<std::size_t>(K0_.nonZeros()), MemoryClass::Device, "ADMM K1 values"),
      k1Assemble_(context, "admm_k1_assemble", 7, sizeof(K1AssemblePush)),
      valuesUpdate_(context),
      scaledValues_(context, "admm_scaled_values", 4, sizeof(ElementCountPush)),
      scaledUpdate_(context),
      block_(blockSize(settings.preconditionerBlock, n_)),
      inverseBlocks_(context, static_cast<std::size_t>(n_) * block_, MemoryClass::Device,
                     "ADMM preconditioner blocks"),
      rhoRows_(context, m_, MemoryClass::Device, "ADMM rho per row"),
      rowScales_(context, m_, MemoryClass::Device, "ADMM rho scale per row"),
      admmRowScales_(context, m_, MemoryClass::Device, "ADMM rho scale per row (kept)"),
      blockFailure_(context, 1, MemoryClass::Host, "ADMM preconditioner status"),
      coarseFailure_(context, 1, MemoryClass::Host, "ADMM multigrid status"),
      recording_(recording),
      unitsPerDispatch_(unitsPerDispatch),
      spmvDot_(context, "pcg_spmv_dot", 6, sizeof(PcgSpmvDotPush)),
      step_(context, "pcg_step", 8, sizeof(PcgStepPush)),
      direction_(context, "pcg_direction", 3, sizeof(PcgDirectionPush)),
      reduce_(context, "la_reduce", 2, sizeof(ReducePush)),
      control_(context, "pcg_control", 3, sizeof(ControlPush)),
      rhs_(context, "admm_rhs", 4, sizeof(RhsPush)),
      update_(context, "admm_update", 7, sizeof(UpdatePush)),
      support_(context, "admm_support", 4, sizeof(SupportPush)),
      assemble_(context, "admm_assemble", 5, sizeof(AssemblePush)),
      singleWorkgroup_(context, "admm_single_workgroup", kSingleWorkgroupBuffers, sizeof(SingleWorkgroupPush),
                       singleWorkgroupLanes(context)),
      dot_(context, "la_dot", 3, sizeof(DotPush)),
      relaxedBounds_(context, "admm_relaxed_bounds", 5, sizeof(RelaxedBoundsPush)),
      activeSides_(context, "admm_active_sides", 5, sizeof(ElementCountPush)),
      polishTargets_(context, "admm_polish_targets", 4, sizeof(ElementCountPush)),
      boundViolation_(context, "admm_bound_violation", 4, sizeof(ElementCountPush)),
      negatedMaps_(context, "admm_negated_maps", 2, sizeof(NegatedMapsPush)),
      activeFlags_(context, "admm_active_flags", 2, sizeof(ActiveFlagsPush)),
      saveIterate_(context, "admm_save_iterate", 9, sizeof(SaveIteratePush)),
      assembly_(context),
      innerIterations_(withinSolverLimit(kInitialInnerIterations)) {
  C_.makeCompressed();
  Ct_.makeCompressed();
  k0Values_.upload({K0_.valuePtr(), static_cast<std::size_t>(K0_.nonZeros())});
  // What K1's and C^T's values are made of on the device, from the patterns (once).
  {
    const K1Terms terms = k1Terms(C_, K0_);
    k1TermOffsets_ = uploaded(context, terms.offsets, "ADMM K1 term offsets");
    k1TermA_ = uploaded(context, terms.a, "ADMM K1 terms");
    k1TermB_ = uploaded(context, terms.b, "ADMM K1 terms");
    cEntryRows_ = uploaded(context, terms.entryRows, "ADMM C entry rows");
  }
  transpose_ = std::make_unique<DeviceGather>(context, compute::transposeTargets(C_),
                                              elementCount(Ct_.nonZeros(), "C's entries"), "ADMM C^T values");
  valuesUpdate_.begin();
  algebra_.gatherSum(valuesUpdate_, *transpose_, devC_.values(), devCt_.values());
  valuesUpdate_.end();
  const compute::BlockMultigridSettings multigridSettings{static_cast<int>(block_)};
  // Automatic: the cycle, or K's whole inverse where K is small (below). The
  // single-workgroup kernel applies the whole inverse but records no cycle, so an explicit
  // single-workgroup recording of a larger K keeps face blocks.
  const bool automatic = settings_.preconditioner == compute::AdmmPreconditioner::Automatic;
  const bool wholeInverse = automatic && static_cast<Index>(n_ / block_) <= kMaxWholeInverseBlocks;
  const bool multigrid = settings_.preconditioner == compute::AdmmPreconditioner::Multigrid ||
                         (automatic && (recording_ != AdmmRecording::SingleWorkgroup || wholeInverse));
  if (settings_.preconditioner == compute::AdmmPreconditioner::Multigrid &&
      recording_ == AdmmRecording::SingleWorkgroup) {
    throwUsage("ADMM: the multigrid preconditioner runs only in the multi-dispatch recording");
  }
  if (multigrid) {
    // Aggregates from K at rho = 1 with every row an inequality row: the couplings'
    // pattern and rough sizes, which is all the pairing needs; they stay for every rho.
    // A C given by its pattern only (values formed on the device later, from scales:
    // setConstraintScaling) couples nothing yet; its pattern with unit entries stands in.
    // Without it every face stayed alone, the multigrid was dropped, and the cube's
    // 384-face PQ level ran block-Jacobi solves of ~360 PCG iterations each.
    const compute::SparseMatrix CtC = aggregationCouplings(C_, Ct_);
    // Automatic, and K small enough: its dense inverse alone, an exact preconditioner (one
    // PCG iteration per solve). A V-cycle over 4-face aggregates is far weaker there: the
    // cube's 96-face PQ level took ~100 PCG iterations per solve with it (307 s on
    // lavapipe) against one (48 s). So were face blocks on K of at most 64 faces (run in
    // the single-workgroup recording before): the 64-face exact step of BM_GlobalStep/vulkan
    // took 3 668 PCG iterations with them and takes 41 (lavapipe 1.9 -> 1.5 s). Not up to
    // the coarsest level's limit: the inversion at each rho update is cubic in K's rows,
    // and at 256 faces (1 024 rows) it cost more than the iterations it saved (a
    // deformation's global step, 30 ADMM iterations: 104 s with 60 PCG iterations, 21.8 s
    // with the two-level cycle's 3 961).
    compute::BlockMultigridSettings aggregationSettings = multigridSettings;
    if (wholeInverse) aggregationSettings.coarsestBlocks = kMaxCoarsestBlocks;
    aggregation_ = std::make_unique<compute::BlockAggregation>(compute::SparseMatrix(K0_ + CtC), aggregationSettings);
    // Coarsening stalls where K couples few blocks (say, faces without shared vertices);
    // the coarsest level is then too large for its dense inverse.
    const Index coarsest = aggregation_->blocks(aggregation_->levelCount() - 1);
    if (coarsest > kMaxCoarsestBlocks) {
      if (settings_.preconditioner == compute::AdmmPreconditioner::Multigrid) {
        throwUsage("ADMM: the multigrid's coarsening stopped at " + std::to_string(coarsest) +
                   " blocks (K couples too few of them), more than the " + std::to_string(kMaxCoarsestBlocks) +
                   " its coarsest level may have; use the block-Jacobi preconditioner");
      }
      aggregation_.reset();  // Automatic: face blocks
    } else if (recording_ == AdmmRecording::SingleWorkgroup && aggregation_->levelCount() > 1) {
      aggregation_.reset();  // Automatic: a cycle this recording cannot run; face blocks
    } else {
      multigrid_ = std::make_unique<Multigrid>(context_, algebra_, *aggregation_, K0_, K0_, settings_.smoothedMultigrid);
    }
  }
}

AdmmKernels::~AdmmKernels() = default;

void AdmmKernels::setRho(const std::vector<char>& equality, double rho) {
  if (equality.size() != m_) throwUsage("ADMM: equality flags for " + std::to_string(equality.size()) + " rows");
  // A new equality pattern (at most once per solve), new values of C or a polish (whose
  // flags replaced the row scales) change K1 = C^T D C and its coarse levels: assembled on
  // the device from the row scales D, which are uploaded only for a new pattern (kept on the
  // device otherwise, and copied into place). A rho update alone moves no mesh-sized data:
  // K, the per-row penalties and the preconditioner's blocks are recomputed on the device;
  // one flag comes back.
  if (!k1Current_ || equality != equality_) {
    if (equality != equality_ || !admmRowScalesHeld_) {
      admmRowScalesHeld_ = false;
      std::vector<double> D(m_);
      for (std::uint32_t i = 0; i < m_; ++i) D[i] = equality[i] ? settings_.equalityRhoScale : 1.0;
      admmRowScales_.upload(D);
      equality_ = equality;
      admmRowScalesHeld_ = true;
    }
    if (m_ > 0) {
      Sequence copy(context_);
      copy.begin();
      copy.copy(admmRowScales_, rowScales_, std::size_t{m_} * sizeof(double));
      copy.end();
      copy.run();
    }
    assembleK1FromRowScales(-1);
    k1Current_ = true;
  }
  assembleK(rho);
  longFirstSolve_ = true;
  if (workspace_) workspace_->lastBlockCount = 0;  // a block from before K changed is not run again
  // The solves after a new rho are harder than those a shrunk cap was sized by.
  if (innerIterations_ < kInitialInnerIterations) {
    innerIterations_ = withinSolverLimit(kInitialInnerIterations);
    if (workspace_) workspace_->blocks.clear();
  }
}

void AdmmKernels::assembleK1(const std::vector<double>& rowScales) {
  rowScales_.upload(rowScales);
  assembleK1FromRowScales(-1);
}

void AdmmKernels::assembleK1FromRowScales(int sidesColumn) {
  const auto nonZeros = static_cast<std::uint32_t>(K0_.nonZeros());
  assembly_.begin();
  if (sidesColumn >= 0) {
    assembly_.dispatch(activeFlags_, {workspace_->sides, rowScales_},
                       ActiveFlagsPush{m_, static_cast<std::uint32_t>(sidesColumn)}, groupsFor(context_, m_));
    assembly_.barrier();
  }
  assembly_.dispatch(k1Assemble_,
                     {k1TermOffsets_, k1TermA_, k1TermB_, devC_.values(), cEntryRows_, rowScales_, k1Values_},
                     K1AssemblePush{nonZeros}, groupsFor(context_, nonZeros));
  assembly_.barrier();
  if (multigrid_) multigrid_->setK1(assembly_, k1Values_);
  assembly_.end();
  assembly_.run();
}

void AdmmKernels::assembleK(double rho) {
  const std::uint32_t noFailure = ~0u;
  blockFailure_.upload({&noFailure, 1});
  const auto nonZeros = static_cast<std::uint32_t>(K0_.nonZeros());
  assembly_.begin();
  assembly_.dispatch(assemble_, {k0Values_, k1Values_, devK_.values(), rowScales_, rhoRows_},
                     AssemblePush{nonZeros, m_, rho}, groupsFor(context_, std::max(nonZeros, m_)));
  assembly_.barrier();
  algebra_.invertDiagonalBlocks(assembly_, devK_, block_, inverseBlocks_, blockFailure_);
  if (multigrid_) {
    coarseFailure_.upload({&noFailure, 1});
    multigrid_->setRho(assembly_, rho, devK_, inverseBlocks_, coarseFailure_);
  }
  assembly_.end();
  assembly_.run();
  std::uint32_t failure = noFailure;
  blockFailure_.download({&failure, 1});
  if (failure != noFailure) {
    const std::uint64_t first = static_cast<std::uint64_t>(failure) * block_;
    throwNumerical("ADMM: the diagonal block of rows " + std::to_string(first) + " to " +
                   std::to_string(first + block_ - 1) + " of K is not positive definite (nor then is K)");
  }
  if (multigrid_) {
    coarseFailure_.download({&failure, 1});
    if (failure == Multigrid::kCoarsestFailure) {
      throwNumerical("ADMM: the coarsest multigrid level of K is not positive definite (nor then is K)");
    }
    if (failure != noFailure) {
      throwNumerical("ADMM: a diagonal block of a coarse multigrid level of K is not positive definite (nor then is K)");
    }
  }
}

void AdmmKernels::setConstraintValues(const compute::SparseMatrix& C) {
  compute::SparseMatrix compressed = C;
  compressed.makeCompressed();
  if (!compute::sameSparsityPattern(compressed, C_)) {
    throwUsage("ADMM: new constraint values on a different sparsity pattern");
  }
  C_ = std::move(compressed);
  devC_.values().upload({C_.valuePtr(), static_cast<std::size_t>(C_.nonZeros())});
  valuesUpdate_.run();  // C^T's values
  k1Current_ = false;   // K1 = C^T D C is assembled again at the next setRho
}

void AdmmKernels::setConstraintScaling(const compute::ConstraintScaling& scaling) {
  compute::checkConstraintScaling(scaling, C_.nonZeros());
  const auto entries = static_cast<std::uint32_t>(C_.nonZeros());
  // Vulkan buffers are never empty: a C without entries keeps one unused element.
  const std::size_t stored = std::max<std::size_t>(entries, 1);
  scaledCoefficients_ = std::make_unique<Array<double>>(context_, stored, MemoryClass::Device, "ADMM C coefficients");
  scaleOf_ = std::make_unique<Array<std::int32_t>>(context_, stored, MemoryClass::Device, "ADMM C scale indices");
  scales_ = std::make_unique<Array<double>>(context_, std::max<std::size_t>(scaling.scaleCount, 1), MemoryClass::Device,
                                            "ADMM C scales");
  if (entries == 0) return;
  scaledCoefficients_->upload(scaling.coefficients);
  scaleOf_->upload(scaling.scaleOf);
  scaledUpdate_.begin();
  scaledUpdate_.dispatch(scaledValues_, {*scaledCoefficients_, *scaleOf_, *scales_, devC_.values()}, ElementCountPush{entries},
                         groupsFor(context_, entries));
  scaledUpdate_.barrier();
  algebra_.gatherSum(scaledUpdate_, *transpose_, devC_.values(), devCt_.values());
  scaledUpdate_.end();
}

void AdmmKernels::setConstraintScales(std::span<const double> scales) {
  if (!scales_) throwUsage("ADMM: constraint scales given before a constraint scaling");
  k1Current_ = false;  // K1 = C^T D C is assembled again at the next setRho
  if (C_.nonZeros() == 0 || scales.empty()) return;
  scales_->upload(scales);
  scaledUpdate_.run();
}

void AdmmKernels::setDeviceConstraintScales(const compute::DeviceMatrix& scales) {
  const Array<double>* array = scales.cols() == 1 ? arrayOf(scales, context_, ArrayLayout::ColumnMajor) : nullptr;
  if (!array) {  // host values, or another context's
    const Eigen::MatrixXd& values = scales.values();
    setConstraintScales({values.data(), static_cast<std::size_t>(values.size())});
    return;
  }
  if (!scales_) throwUsage("ADMM: constraint scales given before a constraint scaling");
  k1Current_ = false;
  if (C_.nonZeros() == 0 || scales.size() == 0) return;
  // Copied where they are (the fit kernel's induced scales), then formed as uploaded ones.
  Sequence copy(context_);
  copy.begin();
  copy.copy(*array, *scales_, static_cast<std::size_t>(scales.size()) * sizeof(double));
  copy.end();
  copy.run();
  scaledUpdate_.run();
}

namespace {

std::uint64_t longestRow(const compute::SparseMatrix& A) {
  std::uint64_t longest = 0;
  for (Eigen::Index r = 0; r < A.outerSize(); ++r) {
    longest = std::max<std::uint64_t>(longest, A.outerIndexPtr()[r + 1] - A.outerIndexPtr()[r]);
  }
  return longest;
}

}  // namespace

std::uint32_t AdmmKernels::singleWorkgroupBudget(std::uint32_t k) const {
  if (unitsPerDispatch_ > 0) return unitsPerDispatch_;
  if (!isCpuDevice(context_)) return kGpuUnitsPerDispatch;
  // Loop back-edges of one invocation per unit of work (shaders/admm_single_workgroup.comp),
  // bounded from above: rows per invocation times the longest rows, plus the reductions.
  const std::uint64_t group = singleWorkgroupLanes(context_), parts = group / kSingleWorkgroupColumns;
  const std::uint64_t columns = k + 1, maxK = longestRow(K0_) + 1;
  // A reduction of two quantities (the costlier kind): loops over columns and parts, twice.
  const std::uint64_t reduction = 2 * columns * (parts + 2) + 2 * (group / parts + 2) + columns;
  const std::uint64_t rows = (n_ / block_ + group - 1) / group * block_;
  const std::uint64_t constraintRows = (m_ + group - 1) / group;
  // A row of the preconditioner: a block's, or of K's whole inverse, four entries per pass.
  const std::uint64_t preconditionerRow = multigrid_ ? (n_ + 3) / 4 + 4 : block_;
  const std::uint64_t start = rows * columns * (longestRow(Ct_) + maxK + 2 * preconditionerRow + 2) + 2 * reduction;
  const std::uint64_t pcg = rows * columns * (maxK + preconditionerRow + 4) + 2 * reduction + 4 * kSingleWorkgroupColumns;
  const std::uint64_t update = constraintRows * columns * (longestRow(C_) + 2) + rows * columns;
  const std::uint64_t unit = std::max({start, pcg, update}) + 4;
  const std::uint64_t fixed = 8 * kSingleWorkgroupColumns;
  return kCpuLoopBackEdges > fixed + unit ? static_cast<std::uint32_t>((kCpuLoopBackEdges - fixed) / unit) : 0;
}

bool AdmmKernels::useSingleWorkgroup(std::uint32_t k) const {
  const bool fits = k <= kSingleWorkgroupColumns &&
                    context_.info().maxStorageBuffersPerStage >= kSingleWorkgroupBuffers &&
                    singleWorkgroupBudget(k) > 0;
  // The cycle is recorded only in the multi-dispatch PCG; its coarsest level alone (K's
  // whole inverse) the single-workgroup kernel applies itself.
  if (multigrid_ && !multigrid_->wholeInverse()) return false;
  switch (recording_) {
    case AdmmRecording::MultiDispatch: return false;
    case AdmmRecording::Automatic: return fits && n_ <= kSingleWorkgroupUnknowns;
    case AdmmRecording::SingleWorkgroup:
      if (!fits) {
        throwDevice("Vulkan ADMM: the single-workgroup kernel needs at most " +
                    std::to_string(kSingleWorkgroupColumns) + " columns (got " + std::to_string(k) + "), " +
                    std::to_string(kSingleWorkgroupBuffers) + " storage buffers per stage (device offers " +
                    std::to_string(context_.info().maxStorageBuffersPerStage) +
                    ") and, on a CPU device, rows short enough for its loop limit");
      }
      return true;
  }
  return false;
}

bool AdmmKernels::singleWorkgroup() const { return workspace_ && workspace_->singleWorkgroup; }

void AdmmKernels::prepare(std::uint32_t k) {
  if (workspace_ && workspace_->k == k) return;
  workspace_.reset();
  workspace_ = std::make_unique<Workspace>(context_, n_, m_, k);
  Workspace& w = *workspace_;
  w.singleWorkgroup = useSingleWorkgroup(k);
  if (w.singleWorkgroup) w.budget = singleWorkgroupBudget(k);
  LinearAlgebra& la = algebra_;

  w.spmvDotSet = std::make_unique<DescriptorSet>(
      context_, spmvDot_,
      std::initializer_list<BufferRange>{devK_.rowOffsets(), devK_.columns(), devK_.values(), w.p.data(),
                                         w.Kp.data(), w.pcg.partial()});
  w.reduceSet = std::make_unique<DescriptorSet>(context_, reduce_,
                                                std::initializer_list<BufferRange>{w.pcg.partial(), w.pcg.values()});
  w.stepSet = std::make_unique<DescriptorSet>(
      context_, step_,
      std::initializer_list<BufferRange>{w.p.data(), w.Kp.data(), w.xTilde.data(), w.r.data(),
                                         w.preconditioned.data(), inverseBlocks_, w.pcg.values(),
                                         w.pcg.partial()});
  w.directionSet = std::make_unique<DescriptorSet>(
      context_, direction_, std::initializer_list<BufferRange>{w.preconditioned.data(), w.p.data(), w.pcg.values()});
  w.controlSet = std::make_unique<DescriptorSet>(
      context_, control_, std::initializer_list<BufferRange>{w.pcg.values(), w.state, w.arguments});
  if (multigrid_) {
    w.cycleResidual = multigrid_->bind(devK_, inverseBlocks_, w.r, w.preconditioned);
    w.cycleRhs = multigrid_->bind(devK_, inverseBlocks_, w.rhs, w.Kp);
    w.rzSet = std::make_unique<DescriptorSet>(
        context_, dot_, std::initializer_list<BufferRange>{w.r.data(), w.preconditioned.data(), w.pcg.partial()});
  }
  if (w.singleWorkgroup) {
    // Face blocks' inverses, or K's whole inverse (the only multigrid this recording runs).
    const Array<double>& preconditioner = multigrid_ ? *multigrid_->wholeInverse() : inverseBlocks_;
    w.singleWorkgroupSet = std::make_unique<DescriptorSet>(
        context_, singleWorkgroup_,
        std::initializer_list<BufferRange>{
            devK_.rowOffsets(), devK_.columns(), devK_.values(), preconditioner, devC_.rowOffsets(),
            devC_.columns(), devC_.values(), devCt_.rowOffsets(), devCt_.columns(), devCt_.values(), w.q.data(),
            w.x.data(), w.xTilde.data(), w.r.data(), w.preconditioned.data(), w.p.data(), w.Kp.data(),
            w.lower.data(), w.upper.data(), w.y.data(), w.yPrevious.data(), w.z.data(), rhoRows_, w.state});
  }

  Sequence& s = w.check;
  s.begin();
  la.spmv(s, devC_, w.x, w.Cx);
  la.spmv(s, devP_, w.x, w.Px);
  la.spmv(s, devCt_, w.y, w.Cty);
  la.maxAbs(s, w.Cx, -1.0, w.z, w.measures, kPrimal);
  la.maxAbs(s, w.Px, 1.0, w.q, 1.0, w.Cty, w.measures, kDual);
  la.maxAbs(s, w.Cx, w.measures, kCx);
  la.maxAbs(s, w.z, w.measures, kZ);
  la.maxAbs(s, w.Px, w.measures, kPx);
  la.maxAbs(s, w.Cty, w.measures, kCty);
  la.maxAbs(s, w.q, w.measures, kQ);
  la.maxAbs(s, w.x, w.measures, kX);
  la.maxAbs(s, w.y, w.measures, kY);
  la.copy(s, w.y, w.dy);
  la.axpby(s, -1.0, w.yPrevious, 1.0, w.dy);
  la.maxAbs(s, w.dy, w.measures, kDy);
  la.spmv(s, devCt_, w.dy, w.Ctdy);
  la.maxAbs(s, w.Ctdy, w.measures, kCtdy);
  s.dispatch(support_, {w.dy.data(), w.lower.data(), w.upper.data(), w.measures.partial()}, SupportPush{m_},
             w.measures.groups(), k);
  s.barrier();
  la.reduce(s, w.measures, kSupport);
  s.end();
}

bool AdmmKernels::loadLinearTerm(const compute::DeviceMatrix& q) {
  const auto k = elementCount(q.cols(), "the ADMM's column count");
  if (k == 0) {  // nothing to iterate; measure() reports empty norms
    workspace_.reset();
    return false;
  }
  if (q.rows() != static_cast<Eigen::Index>(n_)) throwUsage("Vulkan ADMM: q must have n rows");
  prepare(k);
  Workspace& w = *workspace_;
  // A global step's q = -T of the ideal maps the backend's kernel just computed, left on the
  // device (a DeviceMatrix of theirs) or downloaded (host values equal to them): formed from
  // them where they are, bit for bit the host's.
  // (Face maps of this context in a device matrix: the ideal maps, or the projective fits.)
  const ArraySource* mapsSource = q.factor() == -1.0 ? arraySourceOf(q, context_, ArrayLayout::FaceMapColumns) : nullptr;
  const Array<double>* maps = mapsSource ? mapsSource->arrayIn(context_) : nullptr;
  if (maps) {
    // The attempts of one global step's ε schedule solve with one q (only the bounds widen).
    if (w.residentQGeneration == mapsSource->generation()) return true;
  } else {
    const Eigen::MatrixXd& values = q.values();
    if (w.residentQGeneration == 0 && w.uploadedQ.rows() == values.rows() && w.uploadedQ.cols() == values.cols() &&
        w.uploadedQ == values) {
      return true;
    }
    maps = residentMaps_ ? residentMaps_->holdingNegatedColumns(values) : nullptr;
    if (!maps) {
      w.residentQGeneration = 0;
      uploadIfChanged(w.q, w.uploadedQ, values);
      return true;
    }
  }
  w.uploadedQ.resize(0, 0);  // a run that throws leaves nothing claimed
  w.residentQGeneration = 0;
  const auto faceCount = static_cast<std::uint32_t>(q.rows() / 4);
  Sequence s(context_);
  s.begin();
  s.dispatch(negatedMaps_, {BufferRange(*maps, 0, static_cast<std::size_t>(faceCount) * 16 * sizeof(double)),
                            BufferRange(w.q.data())},
             NegatedMapsPush{faceCount, k}, groupsFor(context_, static_cast<std::size_t>(n_) * k));
  s.end();
  s.run();
  if (mapsSource) {
    w.residentQGeneration = mapsSource->generation();
  } else {
    w.uploadedQ = q.values();
  }
  return true;
}

void AdmmKernels::start(const compute::DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                        const compute::DeviceMatrix& x, const Eigen::MatrixXd& y, compute::WarmStart warm) {
  if (!loadLinearTerm(q)) return;
  workspace_->lower.upload(lower);
  workspace_->upper.upload(upper);
  finishStart(q, x, y, warm, false, 0.0);
}

void AdmmKernels::loadRelaxedBounds(const compute::RelaxedBounds& bounds) {
  Workspace& w = *workspace_;
  if (bounds.centre.rows() != m_ || bounds.centre.cols() != w.k || bounds.relaxed.size() != m_) {
    throwUsage("Vulkan ADMM: relaxed bounds need an m x k centre and one flag per row");
  }
  // An ε schedule's attempts share the centre and the flags, a loop's steps the flags.
  uploadIfChanged(w.centre, w.uploadedCentre, bounds.centre);
  if (m_ > 0 && w.uploadedRelaxed != bounds.relaxed) {
    w.uploadedRelaxed.clear();
    const std::vector<std::uint32_t> flags(bounds.relaxed.begin(), bounds.relaxed.end());
    w.relaxed.upload(flags);
    w.uploadedRelaxed = bounds.relaxed;
  }
}

void AdmmKernels::startRelaxed(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                               const compute::DeviceMatrix& x, const Eigen::MatrixXd& y, compute::WarmStart warm) {
  if (!loadLinearTerm(q)) return;
  loadRelaxedBounds(bounds);
  finishStart(q, x, y, warm, true, bounds.epsilon);
}

std::optional<double> AdmmKernels::violationAt(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                                               const compute::DeviceMatrix& x) {
  if (!loadLinearTerm(q)) return 0.0;
  loadRelaxedBounds(bounds);
  // A measurement, not a solve: an iterate held for a kept start (WarmStart::Kept) is set
  // aside in the block's save slots, free between solves, and put back.
  Workspace& w = *workspace_;
  const bool held = w.iterateHeld;
  LinearAlgebra& la = algebra_;
  if (held) {
    recordedOnce(w.setAside, context_, [&](Sequence& s) {
      la.copy(s, w.x, w.xSaved);
      la.copy(s, w.y, w.ySaved);
    }).run();
  }
  finishStart(q, x, Eigen::MatrixXd(), compute::WarmStart::Given, true, 0.0);  // l = u = the centre
  const double violation = boundViolation();
  if (held) {
    recordedOnce(w.putBack, context_, [&](Sequence& s) {
      la.copy(s, w.xSaved, w.x);
      la.copy(s, w.ySaved, w.y);
    }).run();
  }
  w.iterateHeld = held;
  return violation;
}

void AdmmKernels::finishStart(const compute::DeviceMatrix& q, const compute::DeviceMatrix& x, const Eigen::MatrixXd& y,
                              compute::WarmStart warm, bool relaxedBounds, double epsilon) {
  Workspace& w = *workspace_;
  // A kept start keeps x and y where they are, once a start defined them (a new
  // workspace's buffers hold garbage).
  const bool keep = warm == compute::WarmStart::Kept && w.iterateHeld;
  StartX xStart = StartX::Uploaded;
  if (keep) {
    // x as it is: StartX::Uploaded records nothing for x, and nothing is uploaded.
  } else if (x.size() == 0) {
    xStart = StartX::Zero;
  } else if (x.rows() == q.rows() && x.cols() == q.cols() && x.source() && x.source() == q.source() &&
             x.factor() == -q.factor()) {  // one device matrix and its negation
    xStart = StartX::NegatedQ;
  } else if (x.onHost() && q.onHost() && x.rows() == q.rows() && x.cols() == q.cols() &&
             x.values() == -q.values()) {  // exact: negation rounds nothing
    xStart = StartX::NegatedQ;
  }
  const bool zeroY = !keep && y.size() == 0;
  if (!keep && xStart == StartX::Uploaded) w.x.upload(x.values());
  if (!keep && !zeroY) w.y.upload(y);
  w.iterateHeld = true;
  double state[kStateSize] = {};
  state[kStateEpsilon] = epsilon;
  w.state.upload(state);
  w.innerIterationsSeen = 0.0;
  w.uploadedTolerance = -1.0;
  w.polishStartSaved = false;
  w.relaxedStart = relaxedBounds;
  cappedSolves_ = 0;
  longFirstSolve_ = true;
  const int key = static_cast<int>(xStart) + 3 * (zeroY ? 1 : 0) + 6 * (relaxedBounds ? 1 : 0);
  recordedOnce(w.starts[key], context_, [&](Sequence& s) { recordStart(s, xStart, zeroY, relaxedBounds); }).run();
}

void AdmmKernels::setLinearTolerance(double tolerance) {
  if (!(tolerance >= 0.0)) throwUsage("ADMM: the inner solve's tolerance must be >= 0");
  linearTolerance_ = tolerance;
}

void AdmmKernels::iterate(int count) {
  if (!workspace_ || count <= 0) return;
  workspace_->polishStartSaved = false;
  if (workspace_->uploadedTolerance != linearTolerance_) {
    const double squared = linearTolerance_ * linearTolerance_;
    workspace_->state.upload({&squared, 1}, kLinearTolerance2);
    workspace_->uploadedTolerance = linearTolerance_;
  }
  if (workspace_->singleWorkgroup) {
    iterateSingleWorkgroup(count);
    return;
  }
  block(count, longFirstSolve_).run();
  workspace_->lastBlockCount = count;
  workspace_->lastBlockLong = longFirstSolve_;
  longFirstSolve_ = false;
}

void AdmmKernels::redoBlock(int count, bool longFirstSolve) {
  Workspace& w = *workspace_;
  LinearAlgebra& la = algebra_;
  recordedOnce(w.restore, context_, [&](Sequence& s) {
    la.copy(s, w.xSaved, w.x);
    la.copy(s, w.xTildeSaved, w.xTilde);
    la.copy(s, w.ySaved, w.y);
    la.copy(s, w.zSaved, w.z);
  }).run();
  // The discarded iterations' capped solves do not count; the block's iterations before the
  // saved one capped none.
  const double capped = static_cast<double>(cappedSolves_);
  w.state.upload({&capped, 1}, kCappedSolves);
  block(count, longFirstSolve).run();
}

compute::AdmmMeasures AdmmKernels::measure() {
  compute::AdmmMeasures s;
  if (!workspace_) return s;
  Workspace& w = *workspace_;
  const int largest = withinSolverLimit(kMaxInnerIterations);
  double state[kStateSize];
  w.check.run();
  w.state.download(state);
  // A block with a solve stopped by a cap below the largest runs again with the cap doubled:
  // its inexact steps would have changed the ADMM's path (on a 324-face exact global step 40
  // ADMM iterations and 4 rho updates against the host's 30 and 3). Only a solve capped at
  // the largest cap makes an inexact step. The iterations before the capped one were exact
  // and are kept: the block's remaining iterations run again from the capped one's saved start.
  int remaining = std::exchange(w.lastBlockCount, 0);
  bool longFirst = w.lastBlockLong;
  while (remaining > 0 && !w.singleWorkgroup && static_cast<long>(state[kCappedSolves]) > cappedSolves_ &&
         innerIterations_ < largest) {
    throwIfCancelled("the ADMM iteration");
    const int from = std::clamp(static_cast<int>(state[kSavedIteration]), 0, remaining - 1);
    remaining -= from;
    longFirst = longFirst && from == 0;
    innerIterations_ = std::min(2 * innerIterations_, largest);
    w.blocks.clear();  // re-recorded with the new cap
    redoBlock(remaining, longFirst);
    ++redoneBlocks_;
    w.check.run();
    w.state.download(state);
  }
  const std::vector<double> all = w.measures.read();
  auto slot = [&](std::uint32_t index) {
    Eigen::VectorXd v(w.k);
    for (std::uint32_t c = 0; c < w.k; ++c) v[c] = w.measures.at(all, index, c);
    return v;
  };
  s.primalResidual = slot(kPrimal);
  s.dualResidual = slot(kDual);
  s.Cx = slot(kCx);
  s.z = slot(kZ);
  s.Px = slot(kPx);
  s.Cty = slot(kCty);
  s.q = slot(kQ);
  s.x = slot(kX);
  s.y = slot(kY);
  s.dy = slot(kDy);
  s.Ctdy = slot(kCtdy);
  s.support = slot(kSupport);
  s.linearIterations = static_cast<long>(state[kInnerIterations]);
  s.inexactSolves = static_cast<long>(state[kCappedSolves]);
  if (!w.singleWorkgroup && s.inexactSolves > cappedSolves_ && innerIterations_ < largest) {
    innerIterations_ = std::min(2 * innerIterations_, largest);
    w.blocks.clear();  // re-recorded with the new cap on their next use
  } else if (!w.singleWorkgroup && s.inexactSolves == cappedSolves_ && state[kLargestSolve] > 0.0) {
    // Every recorded iteration past a solve's convergence still costs its (empty)
    // dispatches: the cap shrinks to a margin over the longest solve since start().
    int cap = kMinInnerIterations;
    while (cap < largest && cap < kInnerIterationMargin * state[kLargestSolve]) cap *= 2;
    if (cap < innerIterations_) {
      innerIterations_ = cap;
      w.blocks.clear();
    }
  }
  cappedSolves_ = s.inexactSolves;
  return s;
}

void AdmmKernels::download(Eigen::MatrixXd& x, Eigen::MatrixXd& y, Eigen::MatrixXd& z) {
  downloadSolution(x, &y);
  if (!workspace_) {  // k = 0
    z.resize(m_, 0);
    return;
  }
  workspace_->z.download(z);
}

std::optional<compute::DeviceMatrix> AdmmKernels::solution() {
  if (!workspace_) return compute::DeviceMatrix(Eigen::MatrixXd(n_, 0));  // k = 0: nothing to keep
  Workspace& w = *workspace_;
  ++*solutionGeneration_;  // the last solution's copy is overwritten (or reallocated) below
  if (!solution_ || solution_->m() != w.k) solution_ = std::make_unique<DeviceVectors>(context_, n_, w.k, "ADMM solution");
  Sequence s(context_);
  s.begin();
  algebra_.copy(s, w.x, *solution_);
  s.end();
  s.run();
  const auto rows = static_cast<Eigen::Index>(n_);
  const auto cols = static_cast<Eigen::Index>(w.k);
  return compute::DeviceMatrix(rows, cols,
                               std::make_shared<const ArraySource>(context_, solution_->data(), ArrayLayout::ColumnMajor,
                                                                   rows, cols, *solutionGeneration_,
                                                                   solutionGeneration_));
}

std::optional<double> AdmmKernels::centreDistance(bool relaxedRows) {
  if (!workspace_ || m_ == 0) return 0.0;
  Workspace& w = *workspace_;
  if (!w.relaxedStart) return std::nullopt;
  // l = u = the centre on every row (epsilon 0), or only on the rows not relaxed (the
  // relaxed ones' bounds as wide as doubles go).
  const double epsilon = relaxedRows ? 0.0 : std::numeric_limits<double>::max();
  w.state.upload({&epsilon, 1}, kStateEpsilon);
  Sequence s(context_);
  s.begin();
  const std::uint32_t count = m_ * w.k;
  s.dispatch(relaxedBounds_, {w.centre.data(), w.relaxed, w.state, w.lower.data(), w.upper.data()},
             RelaxedBoundsPush{std::max<std::uint32_t>(m_, 1), count, kStateEpsilon}, groupsFor(context_, count));
  s.end();
  s.run();
  return boundViolation();
}

void AdmmKernels::downloadSolution(Eigen::MatrixXd& x, Eigen::MatrixXd* y) {
  if (!workspace_) {  // k = 0
    x.resize(n_, 0);
    if (y) y->resize(m_, 0);
    return;
  }
  workspace_->x.download(x);
  if (y) workspace_->y.download(*y);
}


}  // namespace plano::vk
