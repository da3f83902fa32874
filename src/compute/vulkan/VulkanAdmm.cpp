#include "compute/vulkan/VulkanAdmm.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "compute/SparsePattern.h"
#include "compute/vulkan/LinearAlgebraPushConstants.h"
#include "compute/vulkan/PcgPushConstants.h"
#include "core/Cancellation.h"
#include "core/Error.h"

namespace plano::vk {
namespace {

// Push constants of the ADMM kernels (layouts of the shaders' Push blocks).
struct ControlPush {
  std::uint32_t m, slotRz, slotBz, mode, groupsColumn, groupsDirection, slotFloor, countLargest;
  double tolerance2, floor2;
  std::uint32_t blockStart, abandonAfterCap;
};
constexpr std::uint32_t kNoFloor = ~0u;
struct RhsPush {
  std::uint32_t rows, count, mode, pad;
  double sigma;
};
struct UpdatePush {
  std::uint32_t m, count, saveDual, pad;
  double alpha;
};
struct SupportPush {
  std::uint32_t n;
};
struct SaveIteratePush {  // admm_save_iterate
  std::uint32_t nk, mk, iteration, always;
};
struct RelaxedBoundsPush {
  std::uint32_t rows, count, epsilonSlot;
};

/// Words of `entries` active sides packed sixteen to a word (admm_active_sides).
std::size_t sideWords(std::size_t entries) { return (entries + 15) / 16; }

std::vector<std::uint32_t> packSides(const std::vector<compute::BoundSide>& sides) {
  std::vector<std::uint32_t> words(sideWords(sides.size()), 0u);
  for (std::size_t e = 0; e < sides.size(); ++e) words[e / 16] |= static_cast<std::uint32_t>(sides[e]) << (2 * (e % 16));
  return words;
}
struct SingleWorkgroupPush {
  std::uint32_t n, m, k, iterations, cap, budget, begin, block;
  double sigma, alpha, tolerance2;
};

// PCG scalar slots (k values each). r.r follows its r.z: pcg_step's paired reduction
// writes both.
// kBz scales the stopping test (b.z of the right-hand side, or of the warm start's residual);
// kRhsBz is b.z where it scales only the rounding floor (the polish's solves).
enum PcgSlot : std::uint32_t { kRzEven = 0, kRrEven, kRzOdd, kRrOdd, kPq, kBz, kRhsBz, kPcgSlots };
// Check scalar slots (k values each), in AdmmMeasures' order.
enum MeasureSlot : std::uint32_t {
  kPrimal = 0, kDual, kCx, kZ, kPx, kCty, kQ, kX, kY, kDy, kCtdy, kSupport, kMeasureSlots
};
// pcg_control's state (with the squared tolerance on ||r|| set by the host), then the
// resumable position of admm_single_workgroup.
enum State : std::uint32_t {
  kDone = 0, kInnerIterations, kCappedSolves, kLinearTolerance2, kRemaining, kPhase, kSolveIterations, kStateRz,
  kStateBz = kStateRz + AdmmKernels::kSingleWorkgroupColumns,
  kStateRr = kStateBz + AdmmKernels::kSingleWorkgroupColumns,
  kStateEpsilon = kStateRr + AdmmKernels::kSingleWorkgroupColumns,  ///< A relaxed start's (admm_relaxed_bounds)
  kSolveStart,    ///< pcg_control: kInnerIterations when the current solve began
  kLargestSolve,  ///< pcg_control: the most iterations a counted solve ran since start()
  kBlockCapped,   ///< pcg_control: kCappedSolves when the current block began
  kSavedIteration,  ///< admm_save_iterate: the iteration of the block whose start is saved
  kStateSize
};
static_assert(kSolveStart == 20 && kLargestSolve == 21 && kBlockCapped == 22 && kSavedIteration == 23,
              "shaders/pcg_control.comp's STATE_SOLVE_START, STATE_LARGEST, STATE_BLOCK_CAPPED and "
              "admm_save_iterate.comp's STATE_SAVED_ITERATION");
// llvmpipe ends all loops of an invocation after 65535 back-edges in total; the
// single-workgroup kernel's budget keeps its estimate below half of that.
constexpr std::uint64_t kCpuLoopBackEdges = 32768;
// On GPUs the budget only keeps one dispatch short (well under a second).
constexpr std::uint32_t kGpuUnitsPerDispatch = 4096;

bool isCpuDevice(const Context& context) { return context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU; }

/// The single-workgroup kernel's size: on CPU devices every invocation pays for every
/// barrier, so fewer; on GPUs more lanes sweep the rows.
std::uint32_t singleWorkgroupSize(const Context& context) { return isCpuDevice(context) ? 64 : 256; }
// pcg_control's indirect arguments (byte offsets of its five triples).
constexpr std::size_t kFusedArguments = 0, kReduceArguments = 12, kDirectionArguments = 24, kPairReduceArguments = 36,
                      kProductArguments = 48;

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

struct CountPush {  // admm_scaled_values
  std::uint32_t count;
};
struct ActiveFlagsPush {  // admm_active_flags
  std::uint32_t m;
  std::uint32_t column;
};
struct NegatedMapsPush {  // admm_negated_maps
  std::uint32_t faceCount;
  std::uint32_t columns;
};
struct K1AssemblePush {  // admm_k1_assemble
  std::uint32_t nonZeros;
};

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

/// For each stored value of C, its position among C^T's (the gather that transposes values).
std::vector<std::int32_t> transposeTargets(const compute::SparseMatrix& C) {
  compute::SparseMatrix positions = C;
  for (Eigen::Index e = 0; e < positions.nonZeros(); ++e) positions.valuePtr()[e] = static_cast<double>(e);
  compute::SparseMatrix transposed = positions.transpose();
  transposed.makeCompressed();
  std::vector<std::int32_t> targets(static_cast<std::size_t>(C.nonZeros()));
  for (Eigen::Index t = 0; t < transposed.nonZeros(); ++t) {
    targets[static_cast<std::size_t>(transposed.valuePtr()[t])] = static_cast<std::int32_t>(t);
  }
  return targets;
}

/// The sequence in `slot`, recorded by `record` on first use (recordings are kept by what
/// sizes them: a block's iteration count, a start's kind).
template <class Record>
Sequence& recordedOnce(std::unique_ptr<Sequence>& slot, Context& context, Record&& record) {
  if (!slot) {
    slot = std::make_unique<Sequence>(context);
    slot->begin();
    record(*slot);
    slot->end();
  }
  return *slot;
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

struct AdmmKernels::Workspace {
  Workspace(Context& context, std::uint32_t n, std::uint32_t m, std::uint32_t k)
      : k(k),
        q(context, n, k, "ADMM q"),
        x(context, n, k, "ADMM x"),
        xTilde(context, n, k, "ADMM xTilde"),
        rhs(context, n, k, "ADMM right-hand side"),
        Ctw(context, n, k, "ADMM C^T (rho z - y)"),
        r(context, n, k, "PCG residual"),
        preconditioned(context, n, k, "PCG preconditioned residual"),
        p(context, n, k, "PCG direction"),
        Kp(context, n, k, "PCG K times direction"),
        Px(context, n, k, "ADMM P x"),
        Cty(context, n, k, "ADMM C^T y"),
        Ctdy(context, n, k, "ADMM C^T dy"),
        lower(context, m, k, "ADMM lower bounds"),
        upper(context, m, k, "ADMM upper bounds"),
        y(context, m, k, "ADMM y"),
        yPrevious(context, m, k, "ADMM previous y"),
        z(context, m, k, "ADMM z"),
        zTilde(context, m, k, "ADMM zTilde"),
        w(context, m, k, "ADMM rho z - y"),
        Cx(context, m, k, "ADMM C x"),
        dy(context, m, k, "ADMM dy"),
        xSaved(context, n, k, "ADMM saved x"),
        xTildeSaved(context, n, k, "ADMM saved xTilde"),
        ySaved(context, m, k, "ADMM saved y"),
        zSaved(context, m, k, "ADMM saved z"),
        centre(context, m, k, "ADMM bound centres"),
        relaxed(context, std::max<std::uint32_t>(m, 1), MemoryClass::Device, "ADMM relaxed rows"),
        violation(context, m, k, "ADMM bound violation"),
        sides(context, std::max<std::size_t>(sideWords(std::size_t{m} * k), 1), MemoryClass::Device,
              "ADMM active sides"),
        pcg(context, kPcgSlots, k, n, 2 * k),
        measures(context, kMeasureSlots, k, std::max(n, m)),
        violationNorms(context, 1, k, std::max(m, 1u)),
        state(context, kStateSize, MemoryClass::Device, "PCG control state"),
        arguments(context, 15, MemoryClass::Device, "PCG indirect arguments"),
        check(context) {}
  std::uint32_t k;
  bool singleWorkgroup = false;
  std::uint32_t budget = 0;                  ///< Units of work per single-workgroup dispatch.
  double expectedInnerIterations = 16.0;     ///< Per solve, from the last block (sizes recordings).
  double innerIterationsSeen = 0.0;          ///< The state's PCG iteration total after the last block.
  double uploadedTolerance = -1.0;           ///< The inner tolerance in the state (-1: none yet).
  std::map<int, std::unique_ptr<Sequence>> resumes;  ///< Resume-only recordings by dispatch count.
  DeviceVectors q, x, xTilde, rhs, Ctw, r, preconditioned, p, Kp, Px, Cty, Ctdy;  // n x k
  DeviceVectors lower, upper, y, yPrevious, z, zTilde, w, Cx, dy;               // m x k
  /// The iterate at the start of the last multi-dispatch block's first capped iteration (or of
  /// its last iteration when none was capped), which measure() runs again from when that
  /// solve stopped at a cap below the largest (redoBlock).
  DeviceVectors xSaved, xTildeSaved, ySaved, zSaved;
  std::unique_ptr<Sequence> restore;  ///< x, xTilde, y, z from the saved ones (recorded on first use).
  int lastBlockCount = 0;             ///< Iterations of the block that measure() may run again (0: none).
  bool lastBlockLong = false;         ///< Whether that block's first solve was a long one.
  DeviceVectors centre;            ///< m x k: a relaxed start's (startRelaxed).
  Array<std::uint32_t> relaxed;    ///< m flags: a relaxed start's.
  DeviceVectors violation;         ///< m x k: boundViolation's scratch.
  Array<std::uint32_t> sides;      ///< The polish's active sides, packed (admm_active_sides).
  DeviceScalars pcg;
  DeviceScalars measures;
  DeviceScalars violationNorms;  ///< boundViolation's, apart from the checks' reads.
  Array<double> state;
  Array<std::uint32_t> arguments;
  // The inner PCG's descriptor sets, built once: a block records thousands of dispatches.
  std::unique_ptr<DescriptorSet> spmvDotSet, reduceSet, stepSet, directionSet, controlSet, singleWorkgroupSet;
  // With the multigrid preconditioner: its cycles z = M r and M rhs (for b.z), and r.z's partial sums.
  std::unique_ptr<Multigrid::Binding> cycleResidual, cycleRhs;
  std::unique_ptr<DescriptorSet> rzSet;
  /// z = clamp(C x, l, u), xTilde = x, yPrevious = y, after what the start's kind forms on
  /// the device (recordStart), by startKey; recorded on first use.
  std::map<int, std::unique_ptr<Sequence>> starts;
  Sequence check;  ///< The inf-norms of AdmmMeasures.
  /// Recorded blocks: multi-dispatch by 2 * iteration count + (first solve long),
  /// single-workgroup by 8192 * iteration count + dispatch count.
  std::map<int, std::unique_ptr<Sequence>> blocks;
  /// refineActiveSet's: the iterate it starts every call from (saved by its first call
  /// after start() or iterate()), and its recordings.
  struct Polish {
    Polish(Context& context, std::uint32_t n, std::uint32_t m, std::uint32_t k)
        : x0(context, n, k, "polish start x"), y0(context, m, k, "polish start y"),
          z0(context, m, k, "polish start z"), xKept(context, n, k, "polish result x"), yKept(context, m, k, "polish result y"), save(context),
          begin(context), solve(context), resume(context), update(context) {}
    DeviceVectors x0, y0;
    DeviceVectors z0;  ///< The ADMM's z: each refinement sets z to its targets, the end restores it.
    DeviceVectors xKept, yKept;  ///< keepResult's: the columns refined since the save, the others x0, y0.
    Sequence save;    ///< x0 = x, y0 = y, z0 = z, and the kept result x0, y0
    Sequence begin;   ///< x = x0, lambda = y = diag(active) y0
    Sequence solve;   ///< The refinement's right-hand side and PCG from xTilde = x.
    Sequence resume;  ///< More PCG iterations from xTilde (a solve stopped by the recorded cap).
    Sequence update;  ///< x = xTilde, lambda += rho diag(active) (C x - b), the norms.
    std::unique_ptr<Sequence> targets;  ///< z = b from the held sides (recorded on first use).
    std::unique_ptr<Sequence> discard;  ///< x = x0, y = y0, z = z0 (recorded on first use).
  };
  std::unique_ptr<Polish> polish;
  bool polishStartSaved = false;
  bool relaxedStart = false;  ///< The last start formed l and u from w.centre and w.relaxed.
  Eigen::MatrixXd uploadedQ;  ///< What w.q holds (start() skips an equal q's upload).
  /// The resident maps' generation whose -T w.q holds (0: none; uploadedQ is then what it holds).
  std::uint64_t residentQGeneration = 0;
  Eigen::MatrixXd uploadedCentre;         ///< What w.centre holds (skipped likewise).
  std::vector<std::uint32_t> heldSides;   ///< What w.sides holds (empty: nothing known).
  std::unique_ptr<Sequence> findSides, measureViolation;
  std::vector<char> uploadedRelaxed;      ///< What w.relaxed holds (skipped likewise).
};

AdmmKernels::AdmmKernels(Context& context, const compute::SparseMatrix& P, const compute::SparseMatrix& C,
                         const compute::AdmmSettings& settings, AdmmRecording recording,
                         std::uint32_t unitsPerDispatch)
    : context_(context),
      settings_(settings),
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
      scaledValues_(context, "admm_scaled_values", 4, sizeof(CountPush)),
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
                       singleWorkgroupSize(context)),
      dot_(context, "la_dot", 3, sizeof(DotPush)),
      relaxedBounds_(context, "admm_relaxed_bounds", 5, sizeof(RelaxedBoundsPush)),
      activeSides_(context, "admm_active_sides", 5, sizeof(CountPush)),
      polishTargets_(context, "admm_polish_targets", 4, sizeof(CountPush)),
      boundViolation_(context, "admm_bound_violation", 4, sizeof(CountPush)),
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
  transpose_ = std::make_unique<DeviceGather>(context, transposeTargets(C_),
                                              elementCount(Ct_.nonZeros(), "C's entries"), "ADMM C^T values");
  valuesUpdate_.begin();
  algebra_.gatherSum(valuesUpdate_, *transpose_, devC_.values(), devCt_.values());
  valuesUpdate_.end();
  const compute::BlockMultigridSettings multigridSettings{static_cast<int>(block_)};
  const bool multigrid =
      settings_.preconditioner == compute::AdmmPreconditioner::Multigrid ||
      (settings_.preconditioner == compute::AdmmPreconditioner::Automatic &&
       recording_ != AdmmRecording::SingleWorkgroup &&
       static_cast<Index>(n_ / block_) > multigridSettings.coarsestBlocks);
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
    // lavapipe) against one (48 s). Not up to the coarsest level's limit: the inversion at
    // each rho update is cubic in K's rows, and at 256 faces (1 024 rows) it cost more than
    // the iterations it saved (a deformation's global step, 30 ADMM iterations: 104 s with
    // 60 PCG iterations, 21.8 s with the two-level cycle's 3 961).
    compute::BlockMultigridSettings aggregationSettings = multigridSettings;
    if (settings_.preconditioner == compute::AdmmPreconditioner::Automatic &&
        static_cast<Index>(n_ / block_) <= kMaxWholeInverseBlocks) {
      aggregationSettings.coarsestBlocks = kMaxCoarsestBlocks;
    }
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
    } else {
      multigrid_ = std::make_unique<Multigrid>(context_, algebra_, *aggregation_, K0_, K0_);
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
    multigrid_->setRho(assembly_, rho, coarseFailure_);
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
  scaledUpdate_.dispatch(scaledValues_, {*scaledCoefficients_, *scaleOf_, *scales_, devC_.values()}, CountPush{entries},
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
  const std::uint64_t group = singleWorkgroupSize(context_), parts = group / kSingleWorkgroupColumns;
  const std::uint64_t columns = k + 1, maxK = longestRow(K0_) + 1;
  // A reduction of two quantities (the costlier kind): loops over columns and parts, twice.
  const std::uint64_t reduction = 2 * columns * (parts + 2) + 2 * (group / parts + 2) + columns;
  const std::uint64_t rows = (n_ / block_ + group - 1) / group * block_;
  const std::uint64_t constraintRows = (m_ + group - 1) / group;
  const std::uint64_t start = rows * columns * (longestRow(Ct_) + maxK + 2 * block_ + 2) + 2 * reduction;
  const std::uint64_t pcg = rows * columns * (maxK + block_ + 4) + 2 * reduction + 4 * kSingleWorkgroupColumns;
  const std::uint64_t update = constraintRows * columns * (longestRow(C_) + 2) + rows * columns;
  const std::uint64_t unit = std::max({start, pcg, update}) + 4;
  const std::uint64_t fixed = 8 * kSingleWorkgroupColumns;
  return kCpuLoopBackEdges > fixed + unit ? static_cast<std::uint32_t>((kCpuLoopBackEdges - fixed) / unit) : 0;
}

bool AdmmKernels::useSingleWorkgroup(std::uint32_t k) const {
  const bool fits = k <= kSingleWorkgroupColumns &&
                    context_.info().maxStorageBuffersPerStage >= kSingleWorkgroupBuffers &&
                    singleWorkgroupBudget(k) > 0;
  if (multigrid_) return false;  // the cycle is recorded only in the multi-dispatch PCG
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
    w.singleWorkgroupSet = std::make_unique<DescriptorSet>(
        context_, singleWorkgroup_,
        std::initializer_list<BufferRange>{
            devK_.rowOffsets(), devK_.columns(), devK_.values(), inverseBlocks_, devC_.rowOffsets(),
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

void AdmmKernels::recordStart(Sequence& s, StartX xStart, bool zeroY, bool relaxedBounds) {
  Workspace& w = *workspace_;
  LinearAlgebra& la = algebra_;
  const auto bytes = [](const DeviceVectors& v) { return std::size_t{v.n()} * v.m() * sizeof(double); };
  // x = -q as 0 - q: nothing of x's last contents (possibly non-finite) enters.
  if (xStart != StartX::Uploaded) s.zero(w.x.data(), bytes(w.x));
  if (zeroY) s.zero(w.y.data(), bytes(w.y));
  if (xStart != StartX::Uploaded || zeroY) s.barrier();
  if (xStart == StartX::NegatedQ) la.axpby(s, -1.0, w.q, 1.0, w.x);
  if (relaxedBounds) {
    const std::uint32_t count = m_ * w.k;
    s.dispatch(relaxedBounds_, {w.centre.data(), w.relaxed, w.state, w.lower.data(), w.upper.data()},
               RelaxedBoundsPush{std::max<std::uint32_t>(m_, 1), count, kStateEpsilon}, groupsFor(context_, count));
    s.barrier();
  }
  la.spmv(s, devC_, w.x, w.zTilde);
  la.clamp(s, w.zTilde, w.lower, w.upper, w.z);
  la.copy(s, w.x, w.xTilde);
  la.copy(s, w.y, w.yPrevious);
}

void AdmmKernels::recordRightHandSide(Sequence& s) {
  Workspace& w = *workspace_;
  const std::uint32_t mk = m_ * w.k;
  const std::uint32_t nk = n_ * w.k;
  // rhs = sigma x - q + C^T (rho z - y)
  s.dispatch(rhs_, {w.z.data(), w.y.data(), rhoRows_, w.w.data()}, RhsPush{m_, mk, 0, 0, settings_.sigma},
             groupsFor(context_, mk));
  s.barrier();
  algebra_.spmv(s, devCt_, w.w, w.Ctw);
  s.dispatch(rhs_, {w.x.data(), w.q.data(), w.Ctw.data(), w.rhs.data()}, RhsPush{n_, nk, 1, 0, settings_.sigma},
             groupsFor(context_, nk));
  s.barrier();
}

void AdmmKernels::recordPcgStart(Sequence& s, SolveTarget target) {
  Workspace& w = *workspace_;
  LinearAlgebra& la = algebra_;
  // PCG start from xTilde: r = rhs - K xTilde, preconditioned = M^-1 r, p = it, r.z, r.r, b.z.
  la.spmv(s, devK_, w.xTilde, w.Kp);
  la.copy(s, w.rhs, w.r);
  la.axpby(s, -1.0, w.Kp, 1.0, w.r);
  if (multigrid_) {
    multigrid_->record(s, *w.cycleResidual, nullptr, 0);
  } else {
    la.applyBlockDiagonal(s, inverseBlocks_, block_, w.r, w.preconditioned);
  }
  la.copy(s, w.preconditioned, w.p);
  la.dot(s, w.r, w.preconditioned, w.pcg, kRzEven);
  la.dot(s, w.r, w.r, w.pcg, kRrEven);
  if (target == SolveTarget::WarmStart) la.dot(s, w.r, w.preconditioned, w.pcg, kBz);
  if (multigrid_) {  // Kp as scratch for M^-1 b
    multigrid_->record(s, *w.cycleRhs, nullptr, 0);
  } else {
    la.applyBlockDiagonal(s, inverseBlocks_, block_, w.rhs, w.Kp);
  }
  la.dot(s, w.rhs, w.Kp, w.pcg, target == SolveTarget::RightHandSide ? kBz : kRhsBz);
}

void AdmmKernels::recordInnerSolve(Sequence& s, int innerIterations, SolveTarget target, bool firstOdd,
                                   bool countLargest, BlockPosition position) {
  Workspace& w = *workspace_;
  const std::uint32_t k = w.k;
  const std::uint32_t nk = n_ * k;

  // A continuation's first iterate is the one the last run's capped solve reached: in the
  // slot that run's parity (its recorded count, `firstOdd`) left its r.z in.
  const bool continuation = target == SolveTarget::Continuation;
  const int parity = continuation && firstOdd ? 1 : 0;
  if (!continuation) recordPcgStart(s, target);

  const std::uint32_t groups = w.pcg.groups();
  // The direction update's and the V-cycle's sweeps (vk::Multigrid::record).
  const std::uint32_t directionGroups = sweepGroupsFor(context_, nk);
  const double tolerance2 = settings_.linearSolver.relativeTolerance * settings_.linearSolver.relativeTolerance;
  // The polish's solves (tol ||r0||) stop at the rounding floor of ||b|| too.
  const std::uint32_t floorSlot = target == SolveTarget::RightHandSide ? kNoFloor : kRhsBz;
  const double floor2 = kPolishRoundingFloor * kPolishRoundingFloor;
  auto control = [&](std::uint32_t mode, std::uint32_t slotRz) {
    const bool first = mode == 0 && position.first;
    const bool abandon = mode == 0 && position.abandonAfterCap;
    s.dispatch(control_, *w.controlSet,
               ControlPush{k, slotRz, kBz, mode, groups, directionGroups, floorSlot, countLargest ? 1u : 0u,
                           tolerance2, floor2, first ? 1u : 0u, abandon ? 1u : 0u},
               1);
    s.barrier();
  };
  control(continuation ? 1 : 0, parity == 0 ? kRzEven : kRzOdd);
  for (int j = 0; j < innerIterations; ++j) {
    // The iteration of vk::PcgSolver; r.z alternates between two slots.
    const std::uint32_t current = (j + parity) % 2 == 0 ? kRzEven : kRzOdd;
    const std::uint32_t next = (j + parity) % 2 == 0 ? kRzOdd : kRzEven;
    s.dispatchIndirect(spmvDot_, *w.spmvDotSet, PcgSpmvDotPush{n_, k}, w.arguments, kProductArguments);
    s.barrier();
    s.dispatchIndirect(reduce_, *w.reduceSet, ReducePush{groups, k, kPq}, w.arguments, kReduceArguments);
    s.barrier();
    s.dispatchIndirect(step_, *w.stepSet, PcgStepPush{n_, k, current, kPq, block_, 1}, w.arguments,
                       kFusedArguments);
    s.barrier();
    if (multigrid_) {
      // The step's z = blockdiag^-1 r and its r.z are replaced: z = M r, then r.z's partial
      // sums (r.r's, from the step, stay), all sized by the control's triples.
      multigrid_->record(s, *w.cycleResidual, &w.arguments, kDirectionArguments);
      s.dispatchIndirect(dot_, *w.rzSet, DotPush{n_}, w.arguments, kFusedArguments);
      s.barrier();
    }
    s.dispatchIndirect(reduce_, *w.reduceSet, ReducePush{groups, k, next}, w.arguments, kPairReduceArguments);
    s.barrier();
    s.dispatchIndirect(direction_, *w.directionSet, PcgDirectionPush{n_, k, next, current}, w.arguments,
                       kDirectionArguments);
    s.barrier();
    control(j + 1 == innerIterations ? 2 : 1, next);
  }
}

void AdmmKernels::recordIteration(Sequence& s, bool saveDual, int innerIterations, bool countLargest,
                                  BlockPosition position) {
  Workspace& w = *workspace_;
  LinearAlgebra& la = algebra_;
  const std::uint32_t mk = m_ * w.k;

  recordRightHandSide(s);
  recordInnerSolve(s, innerIterations, SolveTarget::RightHandSide, false, countLargest, position);

  // zTilde = C xTilde, x = alpha xTilde + (1 - alpha) x, then the z and y updates.
  const double alpha = settings_.relaxation;
  la.spmv(s, devC_, w.xTilde, w.zTilde);
  la.axpby(s, alpha, w.xTilde, 1.0 - alpha, w.x);
  s.dispatch(update_,
             {w.zTilde.data(), w.z.data(), w.y.data(), w.yPrevious.data(), w.lower.data(), w.upper.data(), rhoRows_},
             UpdatePush{m_, mk, saveDual ? 1u : 0u, 0, alpha}, groupsFor(context_, mk));
  s.barrier();
}

void AdmmKernels::recordSingleWorkgroup(Sequence& s, int count, int dispatches, bool begin) {
  Workspace& w = *workspace_;
  const double tolerance = settings_.linearSolver.relativeTolerance;
  const auto cap = static_cast<std::uint32_t>(withinSolverLimit(kMaxInnerIterations));
  const DescriptorSet& set = *w.singleWorkgroupSet;
  for (int d = 0; d < dispatches; ++d) {
    const SingleWorkgroupPush push{n_,    m_,    w.k, static_cast<std::uint32_t>(count), cap, w.budget,
                                   begin && d == 0 ? 1u : 0u, block_, settings_.sigma, settings_.relaxation,
                                   tolerance * tolerance};
    s.dispatch(singleWorkgroup_, set, push, 1);
    s.barrier();
  }
}

void AdmmKernels::iterateSingleWorkgroup(int count) {
  Workspace& w = *workspace_;
  // Dispatches for the expected work (each solve: a start, its PCG iterations, the
  // updates), rounded up to a power of two so that few recordings are kept. A dispatch
  // after the block is done returns at once; a block that needs more resumes below.
  const double units = count * (w.expectedInnerIterations + 2.0);
  int dispatches = 1;
  while (dispatches < 4096 && dispatches * static_cast<double>(w.budget) < units) dispatches *= 2;
  recordedOnce(w.blocks[count * 8192 + dispatches], context_, [&](Sequence& s) {
    recordSingleWorkgroup(s, count, dispatches, true);
  }).run();
  // One read-back per run: the position tells whether the block is done.
  double state[kStateSize];
  w.state.download(state);
  while (state[kRemaining] > 0.0) {
    throwIfCancelled("the ADMM iteration");
    recordedOnce(w.resumes[dispatches], context_, [&](Sequence& s) {
      recordSingleWorkgroup(s, count, dispatches, false);
    }).run();
    w.state.download(state);
  }
  w.expectedInnerIterations = std::max(1.0, (state[kInnerIterations] - w.innerIterationsSeen) / count);
  w.innerIterationsSeen = state[kInnerIterations];
}

Sequence& AdmmKernels::block(int count, bool longFirstSolve) {
  Workspace& w = *workspace_;
  auto& slot = w.blocks[2 * count + (longFirstSolve ? 1 : 0)];
  return recordedOnce(slot, context_, [&](Sequence& s) {
    const int largest = withinSolverLimit(kMaxInnerIterations);
    // A capped solve makes measure() run this block again, from the iteration of that solve,
    // when its cap is below the largest (and the multi-dispatch recording's); the solves
    // after it are then skipped, and the iterations after it no longer save their start.
    const bool abandonAfterCap = !w.singleWorkgroup && innerIterations_ < largest;
    const std::uint32_t nk = n_ * w.k, mk = m_ * w.k;
    // Every solve counts into kLargestSolve but a long first one, whose poor warm start says
    // nothing about the ones that follow.
    for (int i = 0; i < count; ++i) {
      if (i == 0 || abandonAfterCap) {
        s.dispatch(saveIterate_,
                   {w.state, w.x.data(), w.xTilde.data(), w.y.data(), w.z.data(), w.xSaved.data(),
                    w.xTildeSaved.data(), w.ySaved.data(), w.zSaved.data()},
                   SaveIteratePush{nk, mk, static_cast<std::uint32_t>(i), i == 0 ? 1u : 0u},
                   groupsFor(context_, std::max(nk, mk)));
        s.barrier();
      }
      const bool longSolve = i == 0 && longFirstSolve;
      recordIteration(s, i == count - 1, longSolve ? largest : innerIterations_, !longSolve,
                      BlockPosition{i == 0, i > 0 && abandonAfterCap});
    }
  });
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
                        const compute::DeviceMatrix& x, const Eigen::MatrixXd& y) {
  if (!loadLinearTerm(q)) return;
  workspace_->lower.upload(lower);
  workspace_->upper.upload(upper);
  finishStart(q, x, y, false, 0.0);
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
                               const compute::DeviceMatrix& x, const Eigen::MatrixXd& y) {
  if (!loadLinearTerm(q)) return;
  loadRelaxedBounds(bounds);
  finishStart(q, x, y, true, bounds.epsilon);
}

std::optional<double> AdmmKernels::violationAt(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                                               const compute::DeviceMatrix& x) {
  if (!loadLinearTerm(q)) return 0.0;
  loadRelaxedBounds(bounds);
  finishStart(q, x, Eigen::MatrixXd(), true, 0.0);  // l = u = the centre
  return boundViolation();
}

void AdmmKernels::finishStart(const compute::DeviceMatrix& q, const compute::DeviceMatrix& x, const Eigen::MatrixXd& y,
                              bool relaxedBounds, double epsilon) {
  Workspace& w = *workspace_;
  StartX xStart = StartX::Uploaded;
  if (x.size() == 0) {
    xStart = StartX::Zero;
  } else if (x.rows() == q.rows() && x.cols() == q.cols() && x.source() && x.source() == q.source() &&
             x.factor() == -q.factor()) {  // one device matrix and its negation
    xStart = StartX::NegatedQ;
  } else if (x.onHost() && q.onHost() && x.rows() == q.rows() && x.cols() == q.cols() &&
             x.values() == -q.values()) {  // exact: negation rounds nothing
    xStart = StartX::NegatedQ;
  }
  const bool zeroY = y.size() == 0;
  if (xStart == StartX::Uploaded) w.x.upload(x.values());
  if (!zeroY) w.y.upload(y);
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

void AdmmKernels::recordPolish() {
  Workspace& w = *workspace_;
  LinearAlgebra& la = algebra_;
  Workspace::Polish& p = *w.polish;
  const int cap = withinSolverLimit(kPolishInnerIterations);
  p.save.begin();
  la.copy(p.save, w.x, p.x0);
  la.copy(p.save, w.y, p.y0);
  la.copy(p.save, w.z, p.z0);
  la.copy(p.save, w.x, p.xKept);
  la.copy(p.save, w.y, p.yKept);
  p.save.end();
  // rowScales_ holds the active flags (assembleK1), rhoRows_ = rho times them (assembleK).
  p.begin.begin();
  la.copy(p.begin, p.x0, w.x);
  la.scaleRows(p.begin, rowScales_, p.y0, w.y);
  p.begin.end();
  // With z = b the ADMM's right-hand side is the refinement's:
  //   sigma x - q + C^T (rho diag(active) b - lambda).
  p.solve.begin();
  recordRightHandSide(p.solve);
  la.copy(p.solve, w.x, w.xTilde);
  recordInnerSolve(p.solve, cap, SolveTarget::WarmStart);
  p.solve.end();
  // A solve that needs more continues where it stopped, not restarted: a PCG restarted
  // every few dozen iterations converges far slower on the stiff K_A.
  p.resume.begin();
  recordInnerSolve(p.resume, kPolishResumeIterations, SolveTarget::Continuation, cap % 2 == 1);
  p.resume.end();
  // r = diag(active) (C x - b) (in zTilde), lambda += rho r, and r's norm (NaN in x or
  // lambda reaches it).
  p.update.begin();
  la.copy(p.update, w.xTilde, w.x);
  la.spmv(p.update, devC_, w.x, w.Cx);
  la.axpby(p.update, -1.0, w.z, 1.0, w.Cx);
  la.scaleRows(p.update, rowScales_, w.Cx, w.zTilde);
  la.scaleRows(p.update, rhoRows_, w.Cx, w.dy);
  la.axpby(p.update, 1.0, w.dy, 1.0, w.y);
  la.maxAbs(p.update, w.zTilde, w.measures, kPrimal);
  p.update.end();
}

bool AdmmKernels::refineActiveSet(const compute::ActiveSetRefinement& request, Eigen::MatrixXd& x,
                                  Eigen::MatrixXd& y, compute::ActiveSetRefinementInfo& info) {
  // No iterate (k = 0), or no rows to hold (m = 0: the host's unconstrained solve; the
  // device would copy empty vectors, which Vulkan forbids).
  if (!workspace_ || m_ == 0) return false;
  Workspace& w = *workspace_;
  const bool bySides = !request.sides.empty();
  if (request.active.size() != m_ ||
      (bySides ? request.sides.size() != std::size_t{m_} * w.k
               : request.targets.rows() != m_ || request.targets.cols() != w.k)) {
    throwUsage("ADMM: an active set or its targets do not match the " + std::to_string(m_) + " x " +
               std::to_string(w.k) + " constraint values");
  }
  for (const Eigen::Index c : request.columns) {
    if (c < 0 || c >= static_cast<Eigen::Index>(w.k)) throwUsage("ADMM: a polished column is out of range");
  }
  if (!w.polish) {
    w.polish = std::make_unique<Workspace::Polish>(context_, n_, m_, w.k);
    recordPolish();
  }
  Workspace::Polish& p = *w.polish;
  if (!w.polishStartSaved) {
    p.save.run();
    w.polishStartSaved = true;
  }

  if (bySides) {
    // The sides findActiveSides found are on the device already.
    const std::vector<std::uint32_t> packed = packSides(request.sides);
    if (packed != w.heldSides) {
      w.heldSides.clear();
      w.sides.upload(packed);
      w.heldSides = packed;
    }
  }
  // K_A = K0 + rho C^T diag(active) C: the ADMM's K with the active flags as row scales,
  // formed from the sides on the device when the flags are a column's sides (the polish's
  // sets are), else uploaded.
  int sidesColumn = -1;
  if (bySides && !request.columns.empty()) {
    const auto c = static_cast<std::size_t>(request.columns.front());
    bool fromSides = true;
    for (std::uint32_t i = 0; i < m_ && fromSides; ++i) {
      fromSides = (request.sides[c * m_ + i] != compute::BoundSide::Free) == (request.active[i] != 0);
    }
    if (fromSides) sidesColumn = static_cast<int>(c);
  }
  k1Current_ = false;  // K1 is the polish's from here on; the next setRho forms the ADMM's
  longFirstSolve_ = true;
  try {
    if (sidesColumn >= 0) {
      assembleK1FromRowScales(sidesColumn);
    } else {
      std::vector<double> flags(m_);
      for (std::uint32_t i = 0; i < m_; ++i) flags[i] = request.active[i] ? 1.0 : 0.0;
      assembleK1(flags);
    }
    assembleK(request.rho);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::Numerical) throw;
    return true;  // not factored: the ADMM's solution stands
  }
  info.factored = true;
  if (bySides) {
    recordedOnce(p.targets, context_, [&](Sequence& s) {
      const std::uint32_t count = m_ * w.k;
      s.dispatch(polishTargets_, {w.sides, w.lower.data(), w.upper.data(), w.z.data()}, CountPush{count},
                 groupsFor(context_, count));
    }).run();
  } else {
    w.z.upload(request.targets);
  }
  p.begin.run();

  // Only the relative tolerance stops these solves (no bound from ADMM residuals).
  const double noBound = std::numeric_limits<double>::max();
  w.state.upload({&noBound, 1}, kLinearTolerance2);
  w.uploadedTolerance = -1.0;
  double state[kStateSize];
  w.state.download(state);
  const double iterationsBefore = state[kInnerIterations];
  const long maxIterations = std::max(1, settings_.linearSolver.maxIterations);
  double previous = std::numeric_limits<double>::infinity();
  for (int r = 0; r < request.maxRefinements; ++r) {
    throwIfCancelled("the polish");
    const double solveStart = state[kInnerIterations];
    double capped = state[kCappedSolves];
    p.solve.run();
    w.state.download(state);
    while (state[kCappedSolves] > capped && state[kInnerIterations] - solveStart < maxIterations) {
      capped = state[kCappedSolves];
      p.resume.run();  // continues the PCG where the capped run stopped
      w.state.download(state);
    }
    if (state[kCappedSolves] > capped) info.solvesConverged = false;
    p.update.run();
    ++info.refinements;
    const std::vector<double> norms = w.measures.read();
    double residual = 0.0;
    for (const Eigen::Index c : request.columns) {
      const double value = w.measures.at(norms, kPrimal, static_cast<std::uint32_t>(c));
      residual = std::isnan(value) ? value : std::max(residual, value);
      if (std::isnan(residual)) break;
    }
    if (!(residual > request.goal) || residual >= previous) break;  // NaN too: the caller rejects it
    previous = residual;
  }
  info.linearIterations = static_cast<long>(state[kInnerIterations] - iterationsBefore);
  if (!request.keepResult) {
    w.x.download(x);
    w.y.download(y);
    return true;
  }
  // The refined columns join the kept result, which becomes the iterate (columns are
  // contiguous: one copy each).
  Sequence keep(context_);
  keep.begin();
  const std::size_t xBytes = std::size_t{n_} * sizeof(double), yBytes = std::size_t{m_} * sizeof(double);
  for (const Eigen::Index c : request.columns) {
    const auto column = static_cast<std::size_t>(c);
    keep.copy(w.x.data(), p.xKept.data(), xBytes, column * xBytes, column * xBytes);
    keep.copy(w.y.data(), p.yKept.data(), yBytes, column * yBytes, column * yBytes);
  }
  keep.barrier();
  algebra_.copy(keep, p.xKept, w.x);
  algebra_.copy(keep, p.yKept, w.y);
  algebra_.copy(keep, p.z0, w.z);  // the ADMM's z again, not this refinement's targets
  keep.end();
  keep.run();
  return true;
}

bool AdmmKernels::findActiveSides(std::vector<compute::BoundSide>& sides) {
  if (!workspace_ || m_ == 0) return false;
  Workspace& w = *workspace_;
  const std::uint32_t count = m_ * w.k;
  w.heldSides.clear();  // before the run: should it fail, w.sides holds nothing known
  recordedOnce(w.findSides, context_, [&](Sequence& s) {
    s.dispatch(activeSides_, {w.z.data(), w.y.data(), w.lower.data(), w.upper.data(), w.sides}, CountPush{count},
               groupsFor(context_, static_cast<std::uint32_t>(sideWords(count))));
  }).run();
  std::vector<std::uint32_t> words(sideWords(count));
  w.sides.download(words);
  sides.resize(count);
  for (std::size_t e = 0; e < count; ++e) {
    sides[e] = static_cast<compute::BoundSide>((words[e / 16] >> (2 * (e % 16))) & 3u);
  }
  w.heldSides = std::move(words);
  return true;
}

double AdmmKernels::boundViolation() {
  if (!workspace_ || m_ == 0) return 0.0;
  Workspace& w = *workspace_;
  recordedOnce(w.measureViolation, context_, [&](Sequence& s) {
    const std::uint32_t count = m_ * w.k;
    algebra_.spmv(s, devC_, w.x, w.Cx);
    s.dispatch(boundViolation_, {w.Cx.data(), w.lower.data(), w.upper.data(), w.violation.data()}, CountPush{count},
               groupsFor(context_, count));
    s.barrier();
    algebra_.maxAbs(s, w.violation, w.violationNorms, 0);
  }).run();
  const std::vector<double> all = w.violationNorms.read();
  double violation = 0.0;
  for (std::uint32_t c = 0; c < w.k; ++c) {
    const double value = w.violationNorms.at(all, 0, c);
    if (std::isnan(value)) return value;
    violation = std::max(violation, value);
  }
  return violation;
}

void AdmmKernels::discardRefinement() {
  if (!workspace_ || !workspace_->polish || !workspace_->polishStartSaved) {
    throwUsage("ADMM: no refinement to discard");
  }
  Workspace& w = *workspace_;
  Workspace::Polish& p = *w.polish;
  recordedOnce(p.discard, context_, [&](Sequence& s) {
    algebra_.copy(s, p.x0, w.x);
    algebra_.copy(s, p.y0, w.y);
    algebra_.copy(s, p.z0, w.z);
    algebra_.copy(s, p.x0, p.xKept);
    algebra_.copy(s, p.y0, p.yKept);
  }).run();
}

}  // namespace plano::vk
