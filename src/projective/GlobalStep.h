#pragma once
// Global step of the projective-maps paper (§4.2, Eq. 4, with the smoothness term of
// §6.3): the compatible face maps closest to prescribed maps T_f,
//
//   minimize  sum_f ||A_f - T_f||_F^2 + alpha sum_{f,g adjacent} ||A_f - A_g||_F^2
//   subject to  d - eps <= C_s A <= d + eps   (compatibility, Eq. 2)
//               s_{f,i} (p_i, 1) A_f = (q_i, 1)  (positional: fixed vertices and handles)
//
// with the scale factors s_{f,i} = 1 / ((p_i, 1) T_f[:, 3]) induced by the targets and
// held fixed, which makes the problem convex (§4.2).
//
// Structure used (see notes on the framework): with those scale factors the fourth
// columns of the targets already satisfy every row (all weights are 1), and with
// A_f(3, 3) = T_f(3, 3) fixed (the map's scale: the paper fixes it to 1, fitted maps come
// with mean reciprocal scale 1, LocalFit.h) they are the only choice on a face whose plane
// misses the origin (normalized coordinates make this the rule), so A_f[:, 3] = T_f[:, 3].
// The objective weighs face f by the square of T_f's scale. Columns 0..2 are
// three independent QPs with one matrix: one factorization, three right-hand sides.
//
// Compatibility rows: at every unconstrained vertex, the image of its first corner's face
// minus the image of each other corner's face, coordinate-wise, so the row value is a
// position difference in normalized units. At a constrained vertex, every incident face
// gets a positional row instead (which implies compatibility there); positional rows are
// never relaxed.
//
// The ε schedule is the paper's (§5): eps_0 = 1e-2 max|C_s T - d|, multiplied by 10
// until the relaxed problem is feasible, where feasible means: the ADMM (BoxQp.h)
// converged to its primal and dual tolerances. A proven-infeasible, stalled or unconverged
// attempt moves on to the next eps; after `maxEpsilonIncreases` increases, Error(Numerical).
// Attempts whose eps is below what the ADMM's tolerances resolve stall (y drifts without a
// certificate) and stop after a few hundred iterations (AdmmSettings::stallIterations).
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "compute/Backend.h"
#include "projective/BoxQp.h"
#include "projective/ScaledConstraintMatrix.h"
#include "projective/ShapeSpace.h"

namespace plano::projective {

enum class EpsilonStart {
  Relaxed,     ///< The paper: first eps = initialEpsilonFraction * initial violation.
  ExactFirst,  ///< Try eps = 0 first (exactly compatible maps, exactly planar faces).
};

struct GlobalStepSettings {
  double smoothness = 0.0;  ///< alpha of §6.3 (the paper uses 3..4 after prolongation).
  EpsilonStart epsilonStart = EpsilonStart::Relaxed;
  double initialEpsilonFraction = 1e-2;
  double epsilonGrowth = 10.0;
  int maxEpsilonIncreases = 8;
  /// With EpsilonStart::Relaxed, targets whose violation max|C_s T - d| is at most this
  /// (normalized units) are compatible to the ADMM's own absolute tolerance (its default):
  /// the schedule then starts at eps = their violation, which they meet, and the step keeps
  /// them without ADMM iterations. At 1e-2 of such a violation an attempt had to resolve
  /// an eps below 1e-8 (AdmmSettings::epsilonToleranceFraction): one PQ level of 98k faces
  /// of the cube's hierarchy took 1 160 ADMM iterations and 221 s on the CPU for faces
  /// already planar to 0.02 %. 0: every schedule starts at the paper's fraction.
  double compatibleViolation = 1e-6;
  /// Attempts tried between the last failed eps below the targets' violation and the
  /// schedule's next eps, when that one is at least the violation: the targets meet such an
  /// eps, so the step would keep them and make no progress. n attempts split that factor
  /// geometrically (n = 2 and growth 10: 10^(1/3) and 10^(2/3) times the failed eps).
  /// 0: the paper's schedule alone.
  int intermediateAttempts = 0;
  /// A loop's steps skip the attempts at eps up to a fraction of the violation at which an
  /// attempt stalled or reached the ADMM's cap in each of the last two steps, for this many
  /// steps in a row; the step after them tries the whole schedule again (0: every step tries
  /// it). Such attempts stall again while the targets move little from one step to the
  /// next, and a skipped attempt that would have stalled changes little: the next one
  /// starts at the rho it would have started at (a stalled attempt's start rho, which is
  /// restored); the subdivisions measured end the same bit for bit. Two steps, not one: a
  /// level's first step starts from the linear scheme's points, and an attempt that stalled
  /// there converged in the next step (a 3-ring dome's second Catmull-Clark level: 2
  /// iterations, or 5 when skipped after one step).
  /// Measured on the CPU (README, "Skipped attempts"): the Enneper hexagons' first
  /// Catmull-Clark level, whose attempts at 1e-2 and 1e-1 of the violation stall in every
  /// step, spent 65 % of its ADMM iterations in stalled attempts.
  int stalledAttemptSkips = 3;
  /// The QP's settings. On an iterative backend the inner solves with K of more than 128
  /// faces use the aggregation multigrid over faces (compute/BlockMultigrid.h): several
  /// times fewer PCG iterations than face blocks, and the host's ADMM iteration kept where
  /// those drift. Up to 128 faces the multigrid is K's dense inverse alone (one PCG
  /// iteration per solve).
  /// Stiff steps on a device (inner solves of at least 8 PCG iterations per ADMM iteration)
  /// stop at their first converged iteration (AdmmSettings::convergenceCheckSolveIterations):
  /// the ~256-face exact step of BM_GlobalStep/vulkan 30 -> 22 ADMM and 6 208 -> 4 944 PCG
  /// iterations; the CPU's iteration is unchanged.
  /// The cycle's prolongations are smoothed (AdmmSettings::smoothedMultigrid), with the
  /// inner solves' tolerance at 1e-3 of the ADMM's residuals (1e-2 let the smoothed solves
  /// drift the ADMM's iteration): a device deformation of a translational grid (lavapipe,
  /// 2026-12-07, README) took 10 115 -> 6 065 PCG iterations and 27.8 -> 23.5 s on 16x16
  /// faces (8 iterations), 13 554 -> 6 106 and ~110 -> ~76 s on 32x32 (2 iterations),
  /// 22 546 -> 13 052 and 322 -> 294 s on 48x48, its meshes within 2.9e-11 (32x32) and
  /// 2.7e-9 (48x48) of the diagonal from the CPU's.
  /// An ε = 0 attempt solved by the ADMM (an iterative backend's) after one of the last step
  /// starts from that one's multipliers and rho (BoxQpSettings::warmStartEqualities); the
  /// CPU solves those attempts directly.
  BoxQpSettings qp = [] {
    BoxQpSettings s;
    s.preconditioner = compute::AdmmPreconditioner::Automatic;
    s.convergenceCheckSolveIterations = 8;
    s.warmStartEqualities = true;
    s.smoothedMultigrid = true;
    s.linearToleranceFraction = 1e-3;
    return s;
  }();
};

/// One eps of the schedule.
struct EpsilonAttempt {
  double epsilon = 0.0;
  BoxQpStatus status = BoxQpStatus::MaxIterationsReached;
  int iterations = 0;   ///< ADMM iterations.
  bool direct = false;  ///< Solved (or found infeasible) by the direct equality solve (BoxQpInfo::direct).
  /// Not tried (GlobalStepSettings::stalledAttemptSkips): an attempt at this fraction of the
  /// violation stalled in an earlier step; status is Stalled, the outcome expected.
  bool skipped = false;
};

/// What a loop's ε schedules carry from one step to the next (GlobalStepSettings::
/// stalledAttemptSkips).
struct EpsilonScheduleMemory {
  /// The last and the step before's largest eps / violation whose attempt stalled, was
  /// capped, or was skipped (0: none).
  double lastStalledFraction = 0.0;
  double earlierStalledFraction = 0.0;
  int skippingSteps = 0;  ///< Steps in a row that skipped attempts.
};

enum class GlobalStepStatus {
  Solved,      ///< The QP converged for `epsilon`.
  Unchanged,   ///< The targets were already compatible and optimal (returned as given).
};

const char* toString(GlobalStepStatus status);

struct GlobalStepInfo {
  GlobalStepStatus status = GlobalStepStatus::Solved;
  double epsilon = 0.0;              ///< The eps of the accepted solution.
  double initialViolation = 0.0;     ///< max |C_s T - d| of the targets.
  double constraintResidual = 0.0;   ///< max |C_s A - d| of the result (<= eps + tolerance).
  double positionalResidual = 0.0;   ///< max |C_s A - d| over positional rows.
  int admmIterations = 0;            ///< Summed over the attempts.
  int factorizations = 0;
  long linearIterations = 0;         ///< Of the ADMM's (and device polish's) solves, summed (BoxQpInfo).
  bool polished = false;
  /// Of the accepted attempt's polish or direct equality solve (BoxQpInfo::polishRefinements).
  int polishRefinements = 0;
  Index nonPositiveScales = 0;       ///< Corners with shat <= 0 (reported, not an error).
  std::vector<EpsilonAttempt> attempts;
};

class GlobalStep {
 public:
  /// Precompute what depends only on the topology: P = I + alpha L (L the face-adjacency
  /// Laplacian, per matrix entry) and the row layout.
  ///   space        in: the shape space (kept by reference: must outlive this object).
  ///   constrained  in: vertices with positional rows (fixed vertices and handles), unique.
  /// Throws Error(BadInput) for an out-of-range or repeated vertex.
  GlobalStep(compute::Backend& backend, const ShapeSpace& space, std::vector<Index> constrained,
             const GlobalStepSettings& settings = {});

  /// Project the targets onto the compatible shape space.
  ///   targets    in: #F maps T_f (normalized coordinates; T(3, 3) = 1 or a fit's scale).
  ///   positions  in: #constrained x 3 world positions of the constrained vertices, in the
  ///              order given to the constructor (ignored when there are none).
  ///   result     out: the maps A_f and their reciprocal scales (those of the targets).
  /// Throws Error(Numerical) when a target sends a corner to infinity (shat ~ 0), when the
  /// iteration produces NaN, or when the eps schedule is exhausted.
  GlobalStepInfo solve(const std::vector<Eigen::Matrix4d>& targets, const Positions& positions, FaceMaps& result);
  /// The same for affine targets (fourth columns (0, 0, 0, 1): ideal maps) given by their
  /// first three columns, 4 #F x 3 (compute::DeviceIdealMaps::linearColumns), which may stay
  /// on the device that computed them: the QP forms its linear term, warm start and the
  /// initial violation there. Throws as solve() (a non-finite target shows as a non-finite
  /// initial violation), and Error(Usage) for targets of the wrong size.
  GlobalStepInfo solveAffine(const compute::DeviceMatrix& linearColumns, const Positions& positions,
                             FaceMaps& result);
  /// The same with the result's first three columns (4 #F x 3; fourth columns (0, 0, 0, 1))
  /// left where the QP solved for them (a device matrix on a device backend, readable while
  /// this object lives and until its next solve: Error(Usage) after).
  GlobalStepInfo solveAffine(const compute::DeviceMatrix& linearColumns, const Positions& positions,
                             compute::DeviceMatrix& resultColumns);
  /// solve() for projective fits kept where the backend computed them (compute::Backend::
  /// fitProjectiveMapsOnDevice, their scales' vanishing limit kMinimumReciprocalScale): the
  /// targets their first three columns, C_s's values formed from their induced scales, both
  /// where they are; the result's first three columns as solveAffine's (the fourth columns
  /// are the fits', unchanged; its corner weights the fits' scales). Throws as solve().
  GlobalStepInfo solve(const compute::DeviceProjectiveFits& fits, const Positions& positions,
                       compute::DeviceMatrix& resultColumns);
  /// A projection step (§5) where the backend keeps its arrays: the projective fits of the
  /// faces at `current` (#V x 3 normalized positions), then solve(fits, ...). `fits` out:
  /// the fits, whose reciprocal scales are the result's corner weights. Throws as solve().
  GlobalStepInfo solveProjectiveFitsAt(const compute::DeviceMatrix& current, const Positions& positions,
                                       compute::DeviceProjectiveFits& fits, compute::DeviceMatrix& resultColumns);

  /// Below this |shat| a corner is mapped (numerically) to the plane at infinity: no map
  /// sends a vertex there.
  static constexpr double kMinimumReciprocalScale = 1e-10;

  const std::vector<Index>& constrainedVertices() const { return constrained_; }
  const GlobalStepSettings& settings() const { return settings_; }
  /// GlobalStepSettings::intermediateAttempts for the following steps.
  void setIntermediateAttempts(int attempts);

 private:
  /// One row of C_s: corner a's face minus corner b's face (b < 0: positional row).
  struct Row {
    Index vertex;
    Index cornerA;
    Index cornerB;
    Index constrainedSlot;  ///< Index into constrained_ for positional rows, else -1.
  };

  /// The solves after their target checks: T (4 #F x 3) the targets' first three columns,
  /// shat (#corners x 1) their reciprocal scales; x receives the maps' first three columns
  /// (4 #F x 3).
  GlobalStepInfo project(const compute::DeviceMatrix& T, const compute::DeviceMatrix& shat,
                         const Positions& positions, compute::DeviceMatrix& x);

  compute::Backend& backend_;
  const ShapeSpace& space_;
  std::vector<Index> constrained_;
  GlobalStepSettings settings_;
  compute::SparseMatrix P_;
  std::vector<Row> rows_;
  ScaledConstraintMatrix constraints_;  ///< C_s: its pattern once, its values per solve.
  std::unique_ptr<BoxQpSolver> qp_;  ///< Created by the first solve, kept for the next ones.
  EpsilonScheduleMemory scheduleMemory_;
};

/// The paper's ε schedule (§5) on a kept QP, the global steps' (this one's and the multires
/// coarse step's): q = -T, the initial violation max |C T - bounds.centre| measured where
/// the QP runs, eps_0 = initialEpsilonFraction times it (eps = 0 first for ExactFirst), then
/// eps grows by epsilonGrowth until an attempt converges. Each attempt starts from the
/// targets T (4 #F x 3, possibly a device matrix) with zero duals, or, an ε = 0 attempt
/// after the last step's solved one, with that one's (BoxQpSettings::warmStartEqualities,
/// where the ADMM keeps them: the QP's settings must not return duals). x receives the
/// accepted solution where the QP left it; info the violation, the attempts, their iteration counts and the solution's residuals. `what`
/// names the step in errors: Error(Numerical) for a non-finite target (naming its face) or
/// iterate, and for an exhausted schedule. `memory` (may be null: every attempt tried)
/// carries the stalled attempts from one step of a loop to the next (GlobalStepSettings::
/// stalledAttemptSkips).
void solveEpsilonSchedule(BoxQpSolver& qp, const compute::DeviceMatrix& T, compute::RelaxedBounds& bounds,
                          const GlobalStepSettings& settings, const std::string& what, GlobalStepInfo& info,
                          compute::DeviceMatrix& x, EpsilonScheduleMemory* memory = nullptr);

}  // namespace plano::projective
