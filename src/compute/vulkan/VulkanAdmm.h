#pragma once
// The ADMM iteration of compute/Admm.h on the device. P and the patterns of C and C^T are
// uploaded once (C's values again for each new problem of a loop, setConstraintValues); x,
// y, z and the problem data stay on the device for a whole solve, and between two checks
// one recorded command buffer runs the checkInterval iterations: only the check's
// per-column inf-norms (a few dozen doubles) come back.
//
// Sources: VulkanAdmm.cpp (matrices, K's assembly, starts, checks), VulkanAdmmRecording.cpp
// (the recorded iterations and their inner PCG), VulkanAdmmPolish.cpp (the polish's
// refinements); VulkanAdmmWorkspace.h holds what they share.
//
// K = P + sigma I + C^T diag(rho) C: rho takes two values (rho, rho * equalityRhoScale on
// equality rows), so K = K0 + rho K1 with K0 = P + sigma I and K1 = C^T D C (D = 1 or
// equalityRhoScale), both stored on the union sparsity pattern; a rho update is one
// kernel (values), with no host refactorization. K1 is assembled on the device
// (shaders/admm_k1_assemble.comp, from C's values and the pairs of C's entries behind each
// entry of K, listed once per pattern) when the equality pattern or C's values change, and
// so are the multigrid's coarse K1 levels: new values of C cost their upload and nothing
// else on the host.
//
// Inner solve: K xTilde = rhs by PCG warm-started from the previous xTilde, preconditioned
// by the inverses of K's diagonal blocks (AdmmSettings::preconditionerBlock rows each; the
// global step uses one face's four map entries, which K couples strongly: on its QPs a
// cold-started PCG needs 3.7-9x fewer iterations than with Jacobi, and a whole single-level
// deformation 2.5x fewer), or by the aggregation multigrid V-cycle over those blocks
// (AdmmSettings::preconditioner, vk::Multigrid: each PCG iteration runs one cycle after the
// step, recorded and sized like the rest of the iteration). The device inverts the small
// blocks at each rho update. The
// iterations are recorded (a cap per ADMM iteration) and sized through
// indirect dispatches by a one-thread control kernel (shaders/pcg_control.comp): once
// every column has r.z <= tol^2 b.z and ||r|| below the host's bound from the ADMM
// residuals (AdmmSettings::linearToleranceFraction), the remaining recorded iterations are
// empty dispatches. So each solve stops at the tolerance, like a host-driven PCG, without a
// read-back. When a check sees a solve that needed more than the cap, the cap doubles
// (re-recorded), up to kMaxInnerIterations, and the block's iterations from the capped one on
// run again from the iterate that one started at (saved by the block on the device, each
// iteration until a solve is capped): a capped solve's inexact step changes the
// ADMM's path, and the host's exact solves take none. The block's solves after a capped one
// are skipped on the device (pcg_control), since their work would be discarded. Only a solve capped at
// kMaxInnerIterations continues from its warm start in the next ADMM iteration (an
// inexact step, counted in AdmmInfo::inexactSolves). When the solves since the start are short, it shrinks
// (kMinInnerIterations), and a rho update restores at least kInitialInnerIterations. The first iteration after start() or a rho update, whose warm
// start is the poorest, always gets kMaxInnerIterations. A fixed count without the flag would either waste work or stop
// short on every solve.
//
// Small problems take another recording of the same iteration: the whole block between two
// checks runs in one workgroup (shaders/admm_single_workgroup.comp), which loops over the ADMM
// and PCG iterations itself. There a dispatch costs more than the arithmetic it carries, and
// the multi-dispatch recording pays six per PCG iteration, most of them empty. The kernel is
// resumable: each dispatch does a budget of work and saves its position, a recording holds the
// dispatches the last block needed, and a block that needs more runs a resume recording (the
// host reads the kernel's small state after each run to know). Its inner solve stops at the
// tolerance or at kMaxInnerIterations.
#include <algorithm>
#include <map>
#include <memory>

#include "compute/Admm.h"
#include "compute/BlockMultigrid.h"
#include "compute/vulkan/VulkanDeviceMatrix.h"
#include "compute/vulkan/VulkanIdealMaps.h"
#include "compute/vulkan/VulkanLinearAlgebra.h"
#include "compute/vulkan/VulkanMultigrid.h"

namespace plano::vk {

/// How the iterations between two checks are recorded.
enum class AdmmRecording {
  Automatic,        ///< SingleWorkgroup when the problem is small enough, else MultiDispatch.
  SingleWorkgroup,  ///< One dispatch per block (throws Error(Device) where it cannot run).
  MultiDispatch,    ///< Kernels over the whole device, PCG sized by indirect dispatches.
};

class AdmmKernels final : public compute::AdmmKernels {
 public:
  /// Recorded PCG iterations per ADMM iteration: the first cap, and the largest it grows
  /// to. Warm-started solves of consecutive ADMM iterations usually need far fewer; the
  /// cap bounds the recording's size (empty dispatches are not free).
  static constexpr int kInitialInnerIterations = 256;
  static constexpr int kMaxInnerIterations = 1024;
  /// After a check whose block capped no solve, the cap shrinks to the smallest power of two
  /// (at least kMinInnerIterations) over kInnerIterationMargin times the longest solve
  /// since start() (the first solves after start() or a rho update excluded): warm-started
  /// solves of a steady ADMM often need a few iterations, and each recorded one past them
  /// costs its empty dispatches (the cube's second PQ level, 96 faces: ~1 PCG iteration per
  /// solve against 256 recorded; 70.6 -> 46.3 s on lavapipe, the same 4 190 ADMM and 4 214
  /// PCG iterations). The longest since start(), not the last block's, and back to the
  /// initial cap after a rho update: solves of a stiff QP vary by tens of iterations between
  /// blocks, and a capped solve's inexact step changes the ADMM's path (the 144-face exact
  /// step's rho history differed from the host's with a per-block cap).
  static constexpr int kMinInnerIterations = 16;
  static constexpr int kInnerIterationMargin = 4;
  /// Recorded PCG iterations per run of a polish solve (refineActiveSet), which continues
  /// until the solve converges: the recorded ones past convergence still cost their
  /// (empty) dispatches. Warm-started at the ADMM's solution a solve that only needs to
  /// meet tol ||b|| takes tens of iterations; one to tol ||r0|| (SolveTarget::WarmStart,
  /// with the ADMM's tol of 1e-10) hundreds (8x8 grid deformation: about 2 500 per polish
  /// of 5-7 refinements, before the rounding floor below).
  static constexpr int kPolishInnerIterations = 64;
  /// Recorded PCG iterations of each continuation of a polish solve past that cap (even:
  /// a continuation keeps the parity of the r.z slots).
  static constexpr int kPolishResumeIterations = 128;
  static_assert(kPolishResumeIterations % 2 == 0);
  /// A polish solve stops once ||r|| <= this times ||b|| (both in the preconditioner's
  /// norm) whatever its warm start's residual: b - K x is known to some units of rounding
  /// of ||b|| only. Below that, PCG's recurrence residual keeps falling while the iterate
  /// no longer improves. 1e-14 (about 45 units): the 8x8 grid deformation then needs 88 472
  /// PCG iterations instead of 113 224, and agrees with the CPU to 4.4e-12 of the diagonal
  /// (6.7e-13 without the floor; 1.7e-12 with 4e-15, 91 922 iterations).
  static constexpr double kPolishRoundingFloor = 1e-14;
  /// The target of a polish solve with momentum, relative to its warm start's residual:
  /// ||r|| <= this times ||r0|| (plain refinements keep the inner solves' 1e-10, but for
  /// the restart after an accelerated one overshot: refineActiveSet). A
  /// refinement of the method of multipliers needs its step only to a fraction of the
  /// step's own size (an inexact augmented Lagrangian method), the more so where each
  /// refinement gains little: the accelerated ones run where the residual contracts by 0.5
  /// or less per refinement, and r0 shrinks with it. Plain refinements contract fast (~40x
  /// each on the 8x8 grid deformation's polish), which such steps would spoil (there 0.58
  /// for the first with 1e-2, and 30 refinements instead of 5), and they decide the
  /// rounding floor. Measured on the ~256-face exact step's polish, from the ADMM's 1.8e-8
  /// to 1e-13 (VulkanAdmm.ASlowlyContractingPolishIsAcceleratedTowardsTheRoundingFloor), PCG
  /// iterations / refinements / max |x - x_KKT| with every refinement's solves to a
  /// fraction of ||r0||: 1e-10 1 010 / 18 / 3.3e-11; 1e-3 695 / 18 / 3.4e-11; 1e-2 422 /
  /// 18 / 3.6e-11; 1e-1 298 / 24 / 5.6e-11 (the refinements' progress then suffers).
  static constexpr double kPolishSolveTolerance = 1e-2;
  /// Automatic recording uses one workgroup up to this many unknowns per column: one
  /// workgroup then sweeps a vector in at most a few hundred rows per invocation.
  static constexpr std::uint32_t kSingleWorkgroupUnknowns = 1u << 16;
  /// Columns and storage buffers of the single-workgroup kernel.
  static constexpr std::uint32_t kSingleWorkgroupColumns = 4;
  static constexpr std::uint32_t kSingleWorkgroupBuffers = 24;
  /// Largest coarsest multigrid level (blocks) the cycle inverts densely (4 x its target of
  /// 64: coarsening that stalls above this falls back to, or with an explicit choice
  /// refuses for, block-Jacobi).
  static constexpr Index kMaxCoarsestBlocks = 256;
  /// Automatic preconditioning of a K with at most this many blocks (and more than the
  /// cycle's coarsest target) inverts K whole, the cycle's coarsest level alone.
  static constexpr Index kMaxWholeInverseBlocks = 128;

  /// Upload P (n x n), C (m x n) and C^T. Throws Error(Device) when a buffer exceeds the device.
  /// `unitsPerDispatch` > 0 overrides the single-workgroup kernel's work per dispatch
  /// (tests use 1 to make every block resume many times).
  AdmmKernels(Context& context, const compute::SparseMatrix& P, const compute::SparseMatrix& C,
              const compute::AdmmSettings& settings, AdmmRecording recording = AdmmRecording::Automatic,
              std::uint32_t unitsPerDispatch = 0);
  ~AdmmKernels() override;

  /// Face maps that another kernel of this context keeps on the device (the backend's ideal
  /// maps; `maps` must outlive these kernels): start() forms a q that equals minus their
  /// first columns there instead of uploading it.
  void bindResidentMaps(const ResidentFaceMaps* maps) { residentMaps_ = maps; }

  void setRho(const std::vector<char>& equality, double rho) override;
  /// Uploads C's values (C^T's follow on the device); K1 and the multigrid's coarse K1
  /// follow at the next setRho. Buffers, pipelines, recordings, K's pattern and the
  /// aggregates stay.
  void setConstraintValues(const compute::SparseMatrix& C) override;
  /// Uploads the coefficients and scale indices once; each setConstraintScales then uploads
  /// one scale per scale index and forms C's (and C^T's) values on the device
  /// (shaders/admm_scaled_values.comp). The host copy of C keeps its pattern only.
  void setConstraintScaling(const compute::ConstraintScaling& scaling) override;
  void setConstraintScales(std::span<const double> scales) override;
  /// Scales in a device array of this context are copied on the device, others uploaded.
  void setDeviceConstraintScales(const compute::DeviceMatrix& scales) override;
  /// q, the centre and flags of relaxed bounds are uploaded only when they differ from the
  /// last start's, l and u of relaxed bounds are formed on the device
  /// (shaders/admm_relaxed_bounds.comp), and so are warm starts that are empty (zero) or,
  /// for x, equal to -q (the global step's: its targets): an ε schedule's later attempts
  /// then upload nothing mesh-sized.
  /// A q that is minus a device matrix of the backend's resident ideal maps, and an x that is
  /// that matrix, are formed from the maps' array (no copy either way).
  void start(const compute::DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
             const compute::DeviceMatrix& x, const Eigen::MatrixXd& y, compute::WarmStart warm) override;
  void startRelaxed(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                    const compute::DeviceMatrix& x, const Eigen::MatrixXd& y, compute::WarmStart warm) override;
  /// startRelaxed with epsilon 0, then boundViolation(): one check-sized read. The iterate
  /// held for a kept start (WarmStart::Kept) stays: a measurement is not a solve.
  std::optional<double> violationAt(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                                    const compute::DeviceMatrix& x) override;
  void setRelaxation(double alpha) override { relaxation_ = alpha; }
  void iterate(int count) override;
  compute::AdmmMeasures measure() override;
  void setLinearTolerance(double tolerance) override;
  /// Whether the current workspace (after start()) records one dispatch per block.
  bool singleWorkgroup() const;
  /// PCG iterations recorded per ADMM iteration in the current blocks (the cap above).
  int innerIterationCap() const { return innerIterations_; }
  /// Blocks that measure() ran again with a doubled cap since these kernels were made.
  long redoneBlocks() const { return redoneBlocks_; }
  /// Whether the inner PCG is preconditioned by the multigrid V-cycle (else block-Jacobi).
  bool multigrid() const { return multigrid_ != nullptr; }
  /// Levels of the multigrid's cycle (1: K's dense inverse alone, an exact preconditioner:
  /// kMaxWholeInverseBlocks); 0 without a multigrid.
  int multigridLevels() const { return multigrid_ ? aggregation_->levelCount() : 0; }
  void download(Eigen::MatrixXd& x, Eigen::MatrixXd& y, Eigen::MatrixXd& z) override;
  void downloadSolution(Eigen::MatrixXd& x, Eigen::MatrixXd* y) override;
  /// On the device: K_A is assembled as K (the active flags as K1's row scales), each
  /// refinement is the ADMM's right-hand side (with z = b) and inner PCG warm-started at x,
  /// or the step's right-hand side and PCG from zero (ActiveSetRefinement::forSteps, and
  /// after a switch to stiffRho: K_A formed again at it), then one update;
  /// per refinement only the k residual norms and the PCG state come back. Throws
  /// Error(Usage) for an active set or targets of the wrong size.
  bool refineActiveSet(const compute::ActiveSetRefinement& request, Eigen::MatrixXd& x, Eigen::MatrixXd& y,
                       compute::ActiveSetRefinementInfo& info) override;
  /// The sides come back packed two bits each (shaders/admm_active_sides.comp) and stay on
  /// the device: a refinement with those sides forms its targets there
  /// (admm_polish_targets) instead of uploading them.
  bool findActiveSides(std::vector<compute::BoundSide>& sides) override;
  /// One check-sized read (shaders/admm_bound_violation.comp, then the inf-norms).
  double boundViolation() override;
  /// A device copy of x (one copy kernel, nothing read back; an ArraySource, ColumnMajor).
  std::optional<compute::DeviceMatrix> solution() override;
  /// The relaxed bounds formed again with epsilon 0 (or the largest double), then
  /// boundViolation(): one check-sized read. The next start forms its own.
  std::optional<double> centreDistance(bool relaxedRows) override;
  void discardRefinement() override;

 private:
  struct Workspace;  // vectors, scalars and recorded sequences for one column count k
  /// The polish's Nesterov momentum before its `step`-th refinement since a restart (step 0
  /// only remembers the multipliers), recorded on first use.
  Sequence& recordedMomentum(int step);
  /// A recorded PCG iteration count, at most the linear solver's maxIterations (and at least 1).
  int withinSolverLimit(int iterations) const {
    return std::min(iterations, std::max(1, settings_.linearSolver.maxIterations));
  }
  void prepare(std::uint32_t k);
  /// `count` iterations, each saving the iterate it starts from (Workspace::xSaved ...)
  /// while no solve of the block was capped (shaders/admm_save_iterate.comp).
  Sequence& block(int count, bool longFirstSolve);
  /// `count` iterations with the current cap, from the saved start of the last block's capped
  /// iteration (its last `count`).
  void redoBlock(int count, bool longFirstSolve);
  /// K1 = C^T diag(rowScales) C (and its coarse levels), then K = K0 + rho K1 with its
  /// preconditioner; assembleK throws Error(Numerical) for a block that is not positive definite.
  void assembleK1(const std::vector<double>& rowScales);
  /// The same with the row scales already in rowScales_, or (sidesColumn >= 0) formed there
  /// from that column's active sides (shaders/admm_active_flags.comp).
  void assembleK1FromRowScales(int sidesColumn);
  void assembleK(double rho);
  /// How start() sets x: uploaded (or the held one kept), zero, or -q (each formed on the
  /// device but the first).
  enum class StartX { Uploaded, Zero, NegatedQ };
  /// Both starts' first part: the workspace for q's columns, and q (false: no columns,
  /// nothing to start).
  bool loadLinearTerm(const compute::DeviceMatrix& q);
  /// A relaxation's centre and flags, each uploaded only when it changed (Error(Usage) for
  /// the wrong sizes).
  void loadRelaxedBounds(const compute::RelaxedBounds& bounds);
  /// Both starts' last part, after the bounds: the warm starts (uploaded or formed as StartX
  /// says), the state (with a relaxation's epsilon) and the start recording.
  void finishStart(const compute::DeviceMatrix& q, const compute::DeviceMatrix& x, const Eigen::MatrixXd& y,
                   compute::WarmStart warm, bool relaxedBounds, double epsilon);
  /// z = clamp(C x, l, u), xTilde = x, yPrevious = y, after setting x (StartX), zeroing y
  /// and forming relaxed bounds as asked.
  void recordStart(Sequence& s, StartX xStart, bool zeroY, bool relaxedBounds);
  void recordRightHandSide(Sequence& s);
  /// What an inner PCG solve's relative tolerance is relative to.
  enum class SolveTarget {
    RightHandSide,  ///< ||r|| <= tol ||b||: the ADMM's solves.
    /// ||r|| <= tol ||r0||, r0 the warm start's residual: the polish's solves, whose b is
    /// dominated by the stiff rho_P C^T b term, so that tol ||b|| left the answer's soft
    /// directions (those C does not fix, where the objective decides) an error of 1e-6 of
    /// the mesh size after the polish (8x8 grid deformation, lavapipe, rho_P then 1e9).
    /// Or ||r|| <= kPolishRoundingFloor ||b||: a warm start whose residual is rounding
    /// already (a refinement past the solution) cannot reach tol ||r0||.
    WarmStart,
    /// No start: the last run's solve, stopped by its recorded cap, goes on with its
    /// iterate, direction and target. That run recorded an odd count when `firstOdd`.
    Continuation,
  };
  /// r = b - K xTilde, its preconditioned residual, the stopping target's b.z and, for the
  /// polish's solves, b's (the rounding floor's scale).
  void recordPcgStart(Sequence& s, SolveTarget target);
  /// A solve's place in an ADMM block (block()).
  struct BlockPosition {
    bool first;            ///< The block's first solve: notes the capped solves so far.
    bool abandonAfterCap;  ///< Skipped when a solve of the block before it was capped.
  };
  /// `tolerance`: the relative one of the target (of ||b|| or ||r0||; a continuation's must
  /// be its solve's). `countLargest`: the solve's iterations count into the longest solve
  /// (kMinInnerIterations).
  void recordInnerSolve(Sequence& s, int innerIterations, SolveTarget target, double tolerance, bool firstOdd = false,
                        bool countLargest = false, BlockPosition position = {});
  void recordIteration(Sequence& s, bool saveDual, int innerIterations, bool countLargest, BlockPosition position);
  void recordPolish();
  void recordSingleWorkgroup(Sequence& s, int count, int dispatches, bool begin);
  void iterateSingleWorkgroup(int count);
  std::uint32_t singleWorkgroupBudget(std::uint32_t k) const;
  bool useSingleWorkgroup(std::uint32_t k) const;

  Context& context_;
  compute::AdmmSettings settings_;
  double relaxation_;                ///< The over-relaxation of the blocks run next (setRelaxation).
  std::uint32_t n_;
  std::uint32_t m_;
  compute::SparseMatrix C_;          ///< Its values may be stale after setConstraintScales.
  compute::SparseMatrix Ct_;
  compute::SparseMatrix K0_;         ///< P + sigma I on the union pattern (host copy).
  std::vector<char> equality_;       ///< Rows of K1's D = equalityRhoScale.
  bool k1Current_ = false;           ///< k1Values_ and rowScales_ hold K1 and D of equality_ and C.
  LinearAlgebra algebra_;
  DeviceCsrMatrix devP_;
  DeviceCsrMatrix devC_;
  DeviceCsrMatrix devCt_;
  DeviceCsrMatrix devK_;              ///< Values rewritten by every rho update.
  Array<double> k0Values_;
  Array<double> k1Values_;
  /// K1's terms: for each entry of K, pairs (a, b) of C's entries in one row (CSR over K's
  /// entries), and each entry of C's row; shaders/admm_k1_assemble.comp.
  Array<std::int32_t> k1TermOffsets_, k1TermA_, k1TermB_, cEntryRows_;
  std::unique_ptr<DeviceGather> transpose_;  ///< C's values -> C^T's.
  Pipeline k1Assemble_;
  Sequence valuesUpdate_;  ///< C^T's values from C's.
  /// setConstraintScaling's: coefficients, scale indices and the scales of the last step
  /// per stored entry of C; the sequence forms C's values from them, then C^T's.
  std::unique_ptr<Array<double>> scaledCoefficients_, scales_;
  std::unique_ptr<Array<std::int32_t>> scaleOf_;
  Pipeline scaledValues_;
  Sequence scaledUpdate_;
  std::uint32_t block_;               ///< Preconditioner block size (AdmmSettings::preconditionerBlock).
  Array<double> inverseBlocks_;      ///< n / block_ inverse diagonal blocks of K, row-major.
  Array<double> rhoRows_;            ///< rho per constraint row.
  Array<double> rowScales_;          ///< D per constraint row: rhoRows_ = rho D.
  Array<double> admmRowScales_;      ///< The ADMM's D for equality_ (rowScales_ may hold the polish's flags).
  bool admmRowScalesHeld_ = false;   ///< admmRowScales_ holds D for equality_.
  Array<std::uint32_t> blockFailure_;  ///< First block of K that is not positive definite, or ~0.
  std::unique_ptr<compute::BlockAggregation> aggregation_;  ///< AdmmPreconditioner::Multigrid only.
  std::unique_ptr<Multigrid> multigrid_;
  Array<std::uint32_t> coarseFailure_;  ///< A coarse level's block that is not positive definite, or ~0.
  AdmmRecording recording_;
  std::uint32_t unitsPerDispatch_;
  Pipeline spmvDot_, step_, direction_, reduce_, control_, rhs_, update_, support_, assemble_, singleWorkgroup_, dot_;
  Pipeline relaxedBounds_, activeSides_, polishTargets_, boundViolation_, negatedMaps_, activeFlags_, saveIterate_;
  const ResidentFaceMaps* residentMaps_ = nullptr;
  Sequence assembly_;
  int innerIterations_;              ///< The current cap.
  long cappedSolves_ = 0;            ///< Capped solves seen at the last check.
  long redoneBlocks_ = 0;
  bool longFirstSolve_ = true;       ///< The next block starts after start() or setRho().
  double linearTolerance_ = 0.0;     ///< Bound on each column's ||r|| of the inner solves.
  std::unique_ptr<Workspace> workspace_;
  /// solution()'s copy of x and its generation, watched (weakly) by the copies' sources.
  std::unique_ptr<DeviceVectors> solution_;
  std::shared_ptr<std::uint64_t> solutionGeneration_ = std::make_shared<std::uint64_t>(0);
};

}  // namespace plano::vk
