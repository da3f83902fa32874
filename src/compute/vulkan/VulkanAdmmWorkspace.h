#pragma once
// What the device ADMM's sources share (VulkanAdmm.cpp: set-up, starts, checks;
// VulkanAdmmRecording.cpp: the recorded iterations and their inner PCG;
// VulkanAdmmPolish.cpp: the polish's refinements): the kernels' push-constant layouts, the
// slots of the device scalars and of the control state, and AdmmKernels::Workspace.
// Internal to those files.
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "compute/vulkan/VulkanAdmm.h"

namespace plano::vk::admm {

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
inline std::size_t sideWords(std::size_t entries) { return (entries + 15) / 16; }

inline std::vector<std::uint32_t> packSides(const std::vector<compute::BoundSide>& sides) {
  std::vector<std::uint32_t> words(sideWords(sides.size()), 0u);
  for (std::size_t e = 0; e < sides.size(); ++e) words[e / 16] |= static_cast<std::uint32_t>(sides[e]) << (2 * (e % 16));
  return words;
}
struct SingleWorkgroupPush {
  std::uint32_t n, m, k, iterations, cap, budget, begin, block;
  std::uint32_t dense;  ///< 1: the preconditioner is K's whole inverse, not its blocks'
  std::uint32_t unused;
  double sigma, alpha, tolerance2;
};

// PCG scalar slots (k values each). r.r follows its r.z: pcg_step's paired reduction
// writes both.
// kPcgBz scales the stopping test (b.z of the right-hand side, or of the warm start's residual);
// kPcgRhsBz is b.z where it scales only the rounding floor (the polish's solves).
enum PcgSlot : std::uint32_t { kPcgRzEven = 0, kPcgRrEven, kPcgRzOdd, kPcgRrOdd, kPcgPq, kPcgBz, kPcgRhsBz, kPcgSlots };
// Check scalar slots (k values each), in AdmmMeasures' order.
enum MeasureSlot : std::uint32_t {
  kPrimal = 0, kDual, kCx, kZ, kPx, kCty, kQ, kX, kY, kDy, kCtdy, kSupport, kMeasureSlots
};
// pcg_control's state (with the squared tolerance on ||r|| set by the host), then the
// resumable position of admm_single_workgroup.
enum StateSlot : std::uint32_t {
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
// On GPUs the budget only keeps one dispatch short (well under a second).
constexpr std::uint32_t kGpuUnitsPerDispatch = 4096;

// pcg_control's indirect arguments (byte offsets of its five triples).
constexpr std::size_t kFusedArguments = 0, kReduceArguments = 12, kDirectionArguments = 24, kPairReduceArguments = 36,
                      kProductArguments = 48;

struct ElementCountPush {  // admm_scaled_values, admm_active_sides, admm_polish_targets, admm_bound_violation
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

}  // namespace plano::vk::admm

namespace plano::vk {

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
        sides(context, std::max<std::size_t>(admm::sideWords(std::size_t{m} * k), 1), MemoryClass::Device,
              "ADMM active sides"),
        pcg(context, admm::kPcgSlots, k, n, 2 * k),
        measures(context, admm::kMeasureSlots, k, std::max(n, m)),
        violationNorms(context, 1, k, std::max(m, 1u)),
        state(context, admm::kStateSize, MemoryClass::Device, "PCG control state"),
        arguments(context, 15, MemoryClass::Device, "PCG indirect arguments"),
        check(context) {}
  std::uint32_t k;
  bool singleWorkgroup = false;
  std::uint32_t budget = 0;                  ///< Units of work per single-workgroup dispatch.
  double expectedInnerIterations = 16.0;     ///< Per solve, from the last block (sizes recordings).
  double innerIterationsSeen = 0.0;          ///< The state's PCG iteration total after the last block.
  double uploadedTolerance = -1.0;           ///< The inner tolerance in the state (-1: none yet).
  /// Resume-only recordings by over-relaxation and dispatch count.
  std::map<std::pair<double, int>, std::unique_ptr<Sequence>> resumes;
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
  /// Recorded blocks by their over-relaxation (a push constant) and: multi-dispatch by
  /// 2 * iteration count + (first solve long), single-workgroup by 8192 * iteration count +
  /// dispatch count. An ε schedule alternates between two relaxations (all-equality
  /// attempts and the others), so each keeps its blocks.
  std::map<std::pair<double, int>, std::unique_ptr<Sequence>> blocks;
  /// refineActiveSet's: the iterate it starts every call from (saved by its first call
  /// after start() or iterate()), and its recordings.
  struct Polish {
    Polish(Context& context, std::uint32_t n, std::uint32_t m, std::uint32_t k)
        : x0(context, n, k, "polish start x"), y0(context, m, k, "polish start y"),
          z0(context, m, k, "polish start z"), xKept(context, n, k, "polish result x"), yKept(context, m, k, "polish result y"), save(context),
          begin(context), solve(context), resume(context), looseSolve(context), looseResume(context),
          stepSolve(context), stepResume(context), looseStepSolve(context), looseStepResume(context),
          update(context), stepUpdate(context) {}
    DeviceVectors x0, y0;
    DeviceVectors z0;  ///< The ADMM's z: each refinement sets z to its targets, the end restores it.
    DeviceVectors xKept, yKept;  ///< keepResult's: the columns refined since the save, the others x0, y0.
    Sequence save;    ///< x0 = x, y0 = y, z0 = z, and the kept result x0, y0
    Sequence begin;   ///< x = x0, lambda = y = diag(active) y0
    Sequence solve;   ///< The refinement's right-hand side and PCG from xTilde = x.
    Sequence resume;  ///< More PCG iterations from xTilde (a solve stopped by the recorded cap).
    /// solve and resume to kPolishSolveTolerance ||r0||: the refinements with momentum.
    Sequence looseSolve, looseResume;
    /// The same for the step (ActiveSetRefinement::forSteps): its right-hand side
    /// -(P x + q + C^T (lambda + rho diag(active) (C x - b))) and PCG from xTilde = 0.
    Sequence stepSolve, stepResume, looseStepSolve, looseStepResume;
    Sequence update;  ///< x = xTilde, lambda += rho diag(active) (C x - b), the norms.
    Sequence stepUpdate;  ///< The same with x += xTilde.
    std::unique_ptr<Sequence> targets;  ///< z = b from the held sides (recorded on first use).
    std::unique_ptr<Sequence> discard;  ///< x = x0, y = y0, z = z0 (recorded on first use).
    /// Nesterov's extrapolation of the multipliers before refinement j after a restart:
    /// lambda += beta_j (lambda - lambda'), lambda' = lambda (yPrevious holds lambda'); entry
    /// 0 only remembers lambda (beta_1 = 0). Recorded on first use.
    std::vector<std::unique_ptr<Sequence>> momentum;
  };
  std::unique_ptr<Polish> polish;
  bool polishStartSaved = false;
  /// x and y hold an iterate a start defined (WarmStart::Kept keeps it), not a new buffer's contents.
  bool iterateHeld = false;
  /// violationAt's: x, y to xSaved, ySaved and back (recorded on first use).
  std::unique_ptr<Sequence> setAside, putBack;
  bool relaxedStart = false;  ///< The last start formed l and u from w.centre and w.relaxed.
  Eigen::MatrixXd uploadedQ;  ///< What w.q holds (start() skips an equal q's upload).
  /// The resident maps' generation whose -T w.q holds (0: none; uploadedQ is then what it holds).
  std::uint64_t residentQGeneration = 0;
  Eigen::MatrixXd uploadedCentre;         ///< What w.centre holds (skipped likewise).
  std::vector<std::uint32_t> heldSides;   ///< What w.sides holds (empty: nothing known).
  std::unique_ptr<Sequence> findSides, measureViolation;
  std::vector<char> uploadedRelaxed;      ///< What w.relaxed holds (skipped likewise).
};

}  // namespace plano::vk
