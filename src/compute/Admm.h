#pragma once
// OSQP-style ADMM (Stellato et al. 2020) for box-constrained QPs with k right-hand-side
// columns that share one matrix:
//
//   minimize  sum_c 1/2 x_c^T P x_c + q_c^T x_c   subject to  l_c <= C x_c <= u_c.
//
// The algorithm is split in two so that it exists once:
//  - AdmmSolver (here, host): the control logic. It decides when to check, evaluates the
//    convergence test and the primal-infeasibility certificate from a handful of
//    per-column inf-norms, detects non-finite iterates and adapts rho.
//  - AdmmKernels (per backend): the vector work. start() loads the problem, iterate()
//    runs a block of plain ADMM iterations, measure() returns the inf-norms, setRho()
//    changes K = P + sigma I + C^T diag(rho) C. The host kernels (HostAdmmKernels) run the
//    loop on the host (Eigen, and passes over C's rows on the CPU threads) with a Backend
//    SPD solver; the Vulkan kernels record the same steps as
//    compute shaders, so between two checks nothing but the block's submit crosses the bus.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "compute/Backend.h"

namespace plano::compute {

/// The iterative backends' preconditioner of K in the inner solves.
enum class AdmmPreconditioner {
  BlockJacobi,  ///< Inverses of K's diagonal blocks of preconditionerBlock rows.
  /// An aggregation V-cycle over those blocks (compute/BlockMultigrid.h): several times
  /// fewer PCG iterations on the global step's stiff matrices, each iteration dearer.
  Multigrid,
  /// Multigrid where its coarsening does not stall on a large coarsest level, block-Jacobi
  /// otherwise and in a single-workgroup recording (which has no cycle). A K of few blocks
  /// (vk::AdmmKernels::kMaxWholeInverseBlocks, the smallest problems included) keeps the
  /// cycle's dense coarsest level alone: K's inverse, an exact preconditioner.
  Automatic,
};

/// The state of an ADMM solve at one of its convergence checks (AdmmSettings::onCheck).
struct AdmmCheck {
  int iterations = 0;            ///< ADMM iterations so far in this solve.
  double primalResidual = 0.0;   ///< max ||C x - z||_inf over the columns.
  double primalTolerance = 0.0;  ///< What the primal residual must reach.
  double dualResidual = 0.0;     ///< max ||P x + q + C^T y||_inf over the columns.
  double dualTolerance = 0.0;
  double rho = 0.0;              ///< Of the inequality rows.
  /// Iterations of the inner solves with K since this solve began (AdmmInfo::linearIterations
  /// so far): PCG iterations on an iterative backend, one per solve where K is factored.
  long linearIterations = 0;
};

struct AdmmSettings {
  double rho = 0.1;                      ///< Initial penalty of inequality rows.
  double equalityRhoScale = 1e3;         ///< rho of rows with l = u, relative to rho.
  double sigma = 1e-6;                   ///< Proximal term: keeps K definite for a PSD P.
  double relaxation = 1.6;               ///< Over-relaxation alpha in (0, 2).
  /// The over-relaxation of a problem whose rows are all equalities (l = u: the global
  /// step's ε = 0 attempts where they are solved by the ADMM, on iterative backends), in
  /// (0, 2). z is then the bounds' point, and the iteration is the method of multipliers
  /// with the multiplier step alpha rho: a mode of the constraints that rho makes stiff
  /// (rho c^2 >> 1 for a singular value c of C) shrinks by |1 - alpha| per iteration (0.6
  /// at OSQP's 1.6), a soft one (rho c^2 << 1) by 1 - alpha rho c^2. Measured on lavapipe,
  /// PCG iterations of the inner solves and the polish, 1.6 -> 1.3: the 8x8 grid's
  /// deformation (12 iterations) 61 766 -> 48 114; exact global steps of 256 and 1k faces
  /// 4 549 -> 3 757 and 9 236 -> 8 257. 1.0 took as many (46 650, 3 917, 8 228) but stopped
  /// further from the solution (the 144-face step's x 5e-6 from its KKT solution on the
  /// host and 5e-5 on the device, against 4e-8 and 7.5e-7 at 1.3), leaving more to the polish.
  double equalityRelaxation = 1.3;
  double absoluteTolerance = 1e-6;       ///< eps_abs of the primal and dual residuals (inf-norms).
  double relativeTolerance = 1e-6;       ///< eps_rel, relative to the sizes of the terms.
  /// The dual residual's tolerance is this many times what absoluteTolerance and
  /// relativeTolerance give it (>= 1; the primal one's stays). A local/global loop needs
  /// its global steps' constraints met tightly (planarity rests on them) but their
  /// optimality only as closely as the next local step's refit can tell: PQ subdivision
  /// sets 10 (PqSubdivisionSettings::globalStep).
  double dualToleranceScale = 1.0;
  double infeasibilityTolerance = 1e-6;  ///< eps of the primal infeasibility certificate.
  /// With relaxed bounds (RelaxedBounds: rows within eps of their centre, an eps schedule's
  /// attempt) the primal residual's absolute tolerance is at most this fraction of eps, but
  /// not below 1e-12 (rounding); 0: absoluteTolerance alone. With eps below
  /// absoluteTolerance, an attempt otherwise converged to rows that may miss their bounds
  /// by more than eps itself, with an active set that tolerance leaves open: the backends'
  /// polishes then chose different ones (a multires projection with fits of unit mean
  /// scale, attempts at eps 5e-7 .. 1e-10: meshes 1.5e-6 of the diagonal apart; with 0.1,
  /// within 1e-6).
  double epsilonToleranceFraction = 0.1;
  int maxIterations = 4000;
  int checkInterval = 10;                ///< Residuals and certificates every this many iterations.
  /// Iterations whose inner solves averaged at least this many iterations each over the
  /// last check's block (iterative backends: PCG iterations; 0: never), and whose residuals
  /// fell at a rate that meets their tolerances within the next block, are also checked
  /// for convergence after every iteration up to the next regular check, as OSQP separates
  /// its termination checks from its rho updates (checking every iteration of a long
  /// attempt cost more than it saved: the cube's two Catmull-Clark levels on lavapipe
  /// 65 -> 76 s). rho, the stall windows and the
  /// certificates stay on the checkInterval grid, so the iteration is the same up to the
  /// earlier stop. On a device a check costs about a PCG iteration (a few products and a
  /// read-back of norms), and a stiff step's ADMM iteration hundreds: stopping at the
  /// first converged iteration instead of the next multiple of checkInterval saves up to
  /// checkInterval - 1 of them. A factoring backend's solves count one each, so its
  /// iteration never changes there. The global step sets 8 (GlobalStepSettings::qp).
  int convergenceCheckSolveIterations = 0;
  /// Stop as Stalled when, through this many iterations (0: never), the dual step
  /// ||y_k - y_k-1||_inf stayed constant to `stallChange` (relative) and the primal residual
  /// fell by less than that: y grows linearly, the mark of a problem infeasible, or
  /// feasible only by a margin below the tolerances, where OSQP's iteration can neither
  /// converge (that needs dy -> 0) nor certify. Such attempts of the global step's ε
  /// schedule, which moves on from an unconverged attempt either way, ran into the
  /// iteration cap. Also stop as Stalled when the primal residual fell through the window,
  /// but at a rate that would reach its tolerance only past maxIterations (an attempt
  /// creeping a few percent per window at rho's clamp). The window restarts whenever rho
  /// changes.
  int stallIterations = 200;
  double stallChange = 0.01;
  /// Also stop as Stalled, at a stall window's check, when the dual residual is more than
  /// this many times its tolerance and falls at a rate that would reach the tolerance only
  /// past maxIterations (0: never). Such an attempt would end unconverged at the cap, too
  /// far from optimal to be kept as SolvedInaccurate; the ε schedule moves on either way.
  /// Measured on the CPU, ADMM iterations of `plano subdivide`: double torus (real quads,
  /// one level) 82 890 -> 27 660; 2-ring dome, two four-point levels 7 700 -> 4 570.
  double farDualFactor = 100.0;
  /// An iteration that stops unconverged (the cap, a stall) ends SolvedInaccurate when, at
  /// its last check, the primal residual met its tolerance and the dual residual this
  /// many times its own (< 1: never). As OSQP's "solved inaccurate" (10x tolerances), but
  /// with the primal tolerance kept: the point is feasible, optimal only more loosely.
  /// Such an iteration stops at the stall window's check once its dual residual falls too
  /// slowly to meet its tolerance within the cap, rather than at the cap.
  double inaccurateDualFactor = 10.0;
  bool adaptiveRho = true;
  double adaptiveRhoFactor = 5.0;        ///< Change K only when rho moves by more than this factor.
  /// Iterative backends stop each inner solve with K when ||r||_2 <= relativeTolerance
  /// ||b|| (linearSolver, in the preconditioner's norm) AND ||r||_2 <= this fraction of the
  /// smaller ADMM residual at the last check (never below this fraction of the smaller
  /// convergence tolerance). With stiff equality rows (rho * equalityRhoScale) the
  /// right-hand side is orders of magnitude larger than the residuals, and a tolerance
  /// relative to it alone left solve errors larger than the dual residual: the rho
  /// balance then drifted from the exact iteration's. The inexact step's error enters the
  /// residuals about one to one, so a small fraction keeps the iteration the host's.
  double linearToleranceFraction = 1e-2;
  LinearSolverSettings linearSolver;     ///< Of the solves with K (iterative backends).
  /// Called at every convergence check after the first iterations (every checkInterval
  /// iterations), on the calling thread; may be empty. For progress output: a global step on
  /// a large mesh can run thousands of iterations between its caller's own reports. It may
  /// throw Interrupted (the iterate is consistent at a check) and nothing else.
  std::function<void(const AdmmCheck&)> onCheck;
  /// Rows per block of the iterative backends' block-Jacobi preconditioner of K (1 to 4;
  /// 1 is Jacobi): rows b i .. b i + b - 1 form block i, so n must be a multiple of b.
  /// Unknowns that K couples strongly in small groups (a face's map entries) converge in
  /// several times fewer PCG iterations with their group as a block.
  int preconditionerBlock = 1;
  AdmmPreconditioner preconditioner = AdmmPreconditioner::BlockJacobi;
  /// The multigrid preconditioner's prolongations smoothed (BlockMultigridSettings::
  /// smoothProlongation), its coarse levels formed on the device from K at each rho update:
  /// about half the PCG iterations of the plain cycle. Its solves leave their error in K's
  /// small eigenvalues, so pair it with a smaller linearToleranceFraction (the global step
  /// uses 1e-3): at 1e-2 a 256-face exact step drifted from the host's 20 ADMM iterations to
  /// 30 (VulkanAdmm.SmoothedMultigridKeepsTheHostIterationWithFewerPcgIterationsThanThePlainCycle).
  bool smoothedMultigrid = false;
};

/// The dual residual's tolerance for terms of inf-norm `scale` (the largest of ||P x||,
/// ||C^T y|| and ||q||): the ADMM's convergence test, and the direct equality solves' that
/// mirror it (projective/BoxQp.cpp).
inline double dualToleranceFor(const AdmmSettings& settings, double scale) {
  return settings.dualToleranceScale * (settings.absoluteTolerance + settings.relativeTolerance * scale);
}

enum class AdmmStatus {
  Solved,               ///< Primal and dual residuals below their tolerances.
  PrimalInfeasible,     ///< An infeasibility certificate was found (no x satisfies the bounds).
  MaxIterationsReached, ///< Neither converged nor proven infeasible.
  NonFinite,            ///< NaN or Inf appeared in the iteration.
  /// Not converged, and y drifting linearly or the primal residual falling too slowly to
  /// converge within the cap (AdmmSettings::stallIterations).
  Stalled,
  SolvedInaccurate,     ///< Stopped unconverged, but feasible and near optimal (AdmmSettings::inaccurateDualFactor).
};

struct AdmmInfo {
  AdmmStatus status = AdmmStatus::MaxIterationsReached;
  int iterations = 0;          ///< ADMM iterations.
  int factorizations = 0;      ///< Changes of K (first one + rho updates).
  double primalResidual = 0.0; ///< ||C x - z||_inf over all columns at the last check.
  double dualResidual = 0.0;   ///< ||P x + q + C^T y||_inf over all columns at the last check.
  double rho = 0.0;            ///< Final rho (of inequality rows).
  long linearIterations = 0;   ///< Iterations of the solves with K (1 per direct solve).
  long inexactSolves = 0;      ///< Solves with K stopped by an iteration cap (iterative backends).
};

/// C's values as coefficients[e] / scales[scaleOf[e]] over its stored entries, in its
/// compressed order (the projective global steps' C: a base coordinate over a corner's
/// reciprocal scale factor, projective/ScaledConstraintMatrix.h). Given once to a solver,
/// after which one scale per corner, not C's values, changes C (AdmmSolver::setConstraintScales).
struct ConstraintScaling {
  std::vector<double> coefficients;  ///< One per stored entry of C.
  std::vector<std::int32_t> scaleOf; ///< One per stored entry of C, in 0 .. scaleCount - 1.
  std::int32_t scaleCount = 0;
};

/// Throws Error(Usage) unless `scaling` has one coefficient and scale index per entry of a
/// C with `nonZeros` entries, each index in range.
void checkConstraintScaling(const ConstraintScaling& scaling, Eigen::Index nonZeros);

/// C's values for these scales (scaling.scaleCount of them, not checked here) into
/// `values`, one per stored entry, in C's compressed order.
void fillScaledValues(const ConstraintScaling& scaling, std::span<const double> scales, double* values);

/// Bounds l <= C x <= u given as a centre widened by epsilon on some rows (the projective
/// global steps' ε relaxation, paper §4.2): l = centre - epsilon and u = centre + epsilon on
/// the rows flagged `relaxed`, l = u = centre on the others. Kernels that keep the iterate on
/// a device form l and u there from a centre they keep (AdmmKernels::startRelaxed): the
/// attempts of an ε schedule, which share the centre and the flags, upload no bounds.
struct RelaxedBounds {
  Eigen::MatrixXd centre;      ///< m x k.
  std::vector<char> relaxed;   ///< m flags.
  double epsilon = 0.0;        ///< >= 0.
  /// l and u; Error(Usage) unless there is one flag per row of the centre.
  Eigen::MatrixXd lower() const { return widened(-epsilon); }
  Eigen::MatrixXd upper() const { return widened(epsilon); }

 private:
  Eigen::MatrixXd widened(double offset) const;
};

/// Per-column inf-norms at the current iterate (vectors of k entries); all a check needs.
/// dy = y - y at the start of the last iteration (zero before the first iteration).
struct AdmmMeasures {
  Eigen::VectorXd primalResidual;  ///< ||C x - z||
  Eigen::VectorXd dualResidual;    ///< ||P x + q + C^T y||
  Eigen::VectorXd Cx, z, Px, Cty, q;  ///< Sizes of the terms (relative tolerances).
  Eigen::VectorXd x, y;            ///< Non-finite detection (NaN propagates into the norm).
  Eigen::VectorXd dy;              ///< ||dy||
  Eigen::VectorXd Ctdy;            ///< ||C^T dy||
  Eigen::VectorXd support;         ///< u^T max(dy, 0) + l^T min(dy, 0) (not a norm).
  long linearIterations = 0;       ///< Since start().
  long inexactSolves = 0;          ///< Since start().
};

/// What a solve starts from (AdmmKernels::start).
enum class WarmStart {
  Given,  ///< The x and y given (zero where empty).
  /// The x and y the kernels hold: their last solve's result (polished where the polish ran
  /// on them), nothing crossing to a device; before any solve, the given ones. For a loop's
  /// next solve of a problem with the same rows and nearby data (OSQP's warm_start); the
  /// caller decides when the held ones are a good start (not after a failed or differently
  /// bounded solve). Both count: with over-relaxation a good y alone is spoilt by the first
  /// step from a poor x (x1 = alpha xTilde + (1 - alpha) x0).
  Kept,
};

/// Which bound the polish holds a row of a column at (AdmmKernels::findActiveSides).
enum class BoundSide : std::uint8_t { Free, Lower, Upper };

/// The polish's refinements with an active set (projective/BoxQp.h), run where the
/// iterate lives (AdmmKernels::refineActiveSet).
struct ActiveSetRefinement {
  std::vector<char> active;            ///< m flags: rows held as equalities.
  Eigen::MatrixXd targets;             ///< m x k: the active rows' values (others ignored).
  std::vector<Eigen::Index> columns;   ///< The columns whose residual decides (others come along).
  double rho = 1e9;                    ///< Penalty of the active rows.
  int maxRefinements = 30;
  double goal = 0.0;                   ///< Stop once the active rows' residual is at most this.
  /// Instead of targets (then empty): the side of each row of each column (m x k,
  /// column-major, as findActiveSides gave them); the targets are those bounds, formed where
  /// the kernels keep them.
  std::vector<BoundSide> sides;
  /// Leave the result where the kernels keep the iterate (x and y are not written): the
  /// caller measures it (boundViolation), keeps it or discards it (discardRefinement), and
  /// fetches what it keeps with download(). Such refinements accumulate: after each, the
  /// iterate holds every column refined since the ADMM's iterate as its last refinement
  /// left it, and the ADMM's other columns (one refinement per active set, merged); z stays
  /// the ADMM's.
  bool keepResult = false;
  /// When > 0: give up once the residual, contracting from here on as it has on average
  /// since the first refinement, would not reach this within maxRefinements (a polish
  /// whose result the caller rejects above it: the refinements left would be spent for
  /// nothing).
  double reach = 0.0;
  /// The refinements start far from the active-set solution (a loop's exact step polished
  /// from the last step's multipliers), where the method of multipliers contracts slowly
  /// from the first refinement on: the kernels that solve iteratively then solve the plain
  /// refinements loosely too, as those with momentum, until one fails to reduce the
  /// residual (the next, tight, decides the rounding floor). Near the solution (the ADMM's
  /// polish) a tight solve lets a fast contraction reach rounding in a few refinements.
  bool farStart = false;
  /// Each refinement solves for its step from the iterate instead of for the new point:
  ///   K_A dx = -(P x + q + C^T lambda) - rho C^T diag(active) (C x - b),   x += dx,
  /// the same refinement in exact arithmetic. The new point's right-hand side carries the
  /// rho-sized term rho C^T b, whose rounding (~1e-16 rho |x|) an iterative solve cannot
  /// get below; the step's shrinks with the residual. So a stiff rho, whose refinements
  /// contract far faster, keeps its accuracy (projective/BoxQp.h, kIterativeExactStepRho).
  /// Each solve then starts from zero, to its tolerance relative to its right-hand side.
  bool forSteps = false;
  /// When > 0 (with a reach): refinements at rho that would not reach `reach` go on from
  /// where they are at this stiffer penalty, solving for their steps (forSteps), instead
  /// of giving up; the reach is then judged again on their own contraction. A mild rho's
  /// refinements for the new point are the cheap ones where they contract (their solves
  /// warm-started near the answer); the stiff ones contract where those crawl.
  double stiffRho = 0.0;
};

/// What refineActiveSet did.
struct ActiveSetRefinementInfo {
  bool factored = false;        ///< Its matrix was formed (positive definite blocks) at all.
  bool solvesConverged = true;  ///< Every inner solve reached its tolerance.
  int refinements = 0;
  long linearIterations = 0;
};

/// The vector work of one backend (see the file comment). Implementations keep x, y, z,
/// xTilde, the previous y and the problem data; the k columns come with start().
class AdmmKernels {
 public:
  virtual ~AdmmKernels() = default;
  /// Set K = P + sigma I + C^T diag(r) C with r_i = rho * (equality[i] ? scale : 1).
  virtual void setRho(const std::vector<char>& equality, double rho) = 0;
  /// Replace C by a matrix with the same sparsity pattern (throws Error(Usage) otherwise);
  /// K changes at the next setRho. What depends on the pattern only (buffers, pipelines, K's
  /// pattern, a factorization's analysis, a multigrid's aggregates) is kept.
  virtual void setConstraintValues(const SparseMatrix& C) = 0;
  /// Keep C's values as this scaling of its entries (checkConstraintScaling against C's
  /// entries: Error(Usage)); setConstraintScales then forms them where C lives.
  virtual void setConstraintScaling(const ConstraintScaling& scaling) = 0;
  /// C's values from new scales (scaling.scaleCount of them, checked by the caller); as
  /// setConstraintValues, K changes at the next setRho.
  virtual void setConstraintScales(std::span<const double> scales) = 0;
  /// setConstraintScales with the scales a device matrix (#scales x 1): kernels that keep C
  /// where the matrix lives form C's values from it there. The default reads its values.
  virtual void setDeviceConstraintScales(const DeviceMatrix& scales) {
    const Eigen::MatrixXd& values = scales.values();
    setConstraintScales({values.data(), static_cast<std::size_t>(values.size())});
  }
  /// Load q (n x k), bounds (m x k) and warm starts x (n x k) and y (m x k), each of which
  /// may be empty for zero (set where the kernels keep the iterate: nothing copied to a
  /// device); z = clamp(C x, l, u), xTilde = x. With WarmStart::Kept the x and y the kernels
  /// hold stay (the given ones serve before any solve). q and x may be device matrices (DeviceMatrix):
  /// kernels that keep the iterate where those live bind them, others read their values.
  virtual void start(const DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                     const DeviceMatrix& x, const Eigen::MatrixXd& y, WarmStart warm) = 0;
  /// start() with l and u given as a relaxation (RelaxedBounds, checked by the caller). The
  /// default forms them on the host; kernels that keep the iterate on a device form them there.
  virtual void startRelaxed(const DeviceMatrix& q, const RelaxedBounds& bounds, const DeviceMatrix& x,
                            const Eigen::MatrixXd& y, WarmStart warm) {
    start(q, bounds.lower(), bounds.upper(), x, y, warm);
  }
  /// The over-relaxation alpha of the following iterate() calls (AdmmSolver sets it before
  /// each solve: AdmmSettings::relaxation, or equalityRelaxation for an all-equality problem).
  virtual void setRelaxation(double alpha) = 0;
  /// `count` ADMM iterations (OSQP Algorithm 1, with the current rho and alpha):
  ///   xTilde = K^-1 (sigma x - q + C^T (rho z - y))   (warm-started at the last xTilde)
  ///   zTilde = C xTilde
  ///   x = alpha xTilde + (1 - alpha) x,  zR = alpha zTilde + (1 - alpha) z
  ///   zNext = clamp(zR + y / rho, l, u),  y += rho (zR - zNext),  z = zNext
  /// The last iteration first saves y for the certificate's dy.
  virtual void iterate(int count) = 0;
  virtual AdmmMeasures measure() = 0;
  /// Absolute bound on each column's ||r||_2 for the inner solves of the following
  /// iterate() calls (AdmmSettings::linearToleranceFraction). Kernels that solve exactly
  /// (a factorization) have nothing to tighten and ignore it.
  virtual void setLinearTolerance(double tolerance) { (void)tolerance; }
  /// The current x, y and z (n x k, m x k, m x k).
  virtual void download(Eigen::MatrixXd& x, Eigen::MatrixXd& y, Eigen::MatrixXd& z) = 0;
  /// x and, when y is not null, y (z serves the host's polish alone).
  virtual void downloadSolution(Eigen::MatrixXd& x, Eigen::MatrixXd* y) {
    Eigen::MatrixXd yAll, z;
    download(x, yAll, z);
    if (y) *y = std::move(yAll);
  }
  /// The polish's method of multipliers on the iterate the last iterate() left (or start()
  /// loaded), where these kernels keep it, so that the polish moves no mesh-sized data per
  /// refinement: with K_A = P + sigma I + rho C^T diag(active) C, lambda = y on the active
  /// rows and 0 elsewhere, each refinement solves
  ///   K_A x' = sigma x - q - C^T lambda + rho C^T diag(active) b   (warm-started at x)
  /// and updates lambda += rho diag(active) (C x' - b), until the active rows' residual
  /// (inf-norm over request.columns) is at most request.goal or stops shrinking. Every call
  /// starts again from that iterate (one call per active set); on exit x (n x k) and y
  /// (m x k, lambda) hold the result for all k columns, request.columns' being the
  /// meaningful ones. K is then K_A's: the next setRho forms the ADMM's again. Returns
  /// false when these kernels have no such step (the caller refines on the host).
  virtual bool refineActiveSet(const ActiveSetRefinement& request, Eigen::MatrixXd& x, Eigen::MatrixXd& y,
                               ActiveSetRefinementInfo& info) {
    (void)request, (void)x, (void)y, (void)info;
    return false;
  }
  /// The polish's active sets at the iterate, found where the kernels keep it, by OSQP's
  /// rule (projective/BoxQp.cpp's): per row and column (m x k, column-major) Lower where
  /// l = u or z - l < -y, else Upper where u - z < y, else Free. Returns false when these
  /// kernels have no such step or no refineActiveSet with sides and keepResult (the caller
  /// then polishes from download()), and then also the two below are not available.
  virtual bool findActiveSides(std::vector<BoundSide>& sides) {
    (void)sides;
    return false;
  }
  /// max(l - C x, C x - u, 0) over all rows and columns at the current x; NaN (or +Inf)
  /// when C x is not finite.
  virtual double boundViolation();
  /// The current x (n x k) as a device matrix whose values stay where the kernels keep the
  /// iterate (a copy there, readable until the next solution() of these kernels: Error(Usage)
  /// after), or nullopt for kernels that do not keep it there (the caller downloads x).
  virtual std::optional<DeviceMatrix> solution() { return std::nullopt; }
  /// After a relaxed start (startRelaxed): max |C x - centre| at the current x over all rows
  /// (`relaxedRows`) or over the rows not relaxed only, measured where the kernels keep the
  /// iterate; the bounds are formed again for the next check. nullopt for kernels that do not
  /// keep the iterate there, or after a start that was not relaxed. NaN when C x is not finite.
  virtual std::optional<double> centreDistance(bool relaxedRows) {
    (void)relaxedRows;
    return std::nullopt;
  }
  /// Start (as startRelaxed, y zero) with bounds.centre as both bounds, and return
  /// boundViolation(): max |C x - centre|, measured where the kernels keep the iterate.
  /// nullopt (nothing started) for kernels that do not keep it there.
  virtual std::optional<double> violationAt(const DeviceMatrix& q, const RelaxedBounds& bounds,
                                            const DeviceMatrix& x) {
    (void)q, (void)bounds, (void)x;
    return std::nullopt;
  }
  /// Make the iterate the one the refinements started from (the ADMM's), after
  /// refinements with keepResult that the caller rejects.
  virtual void discardRefinement();
};

/// The ADMM control logic over a backend's kernels (see the file comment).
class AdmmSolver {
 public:
  AdmmSolver(std::unique_ptr<AdmmKernels> kernels, Eigen::Index n, Eigen::Index m, const AdmmSettings& settings);

  /// Run from the warm starts x (n x k) and y (m x k) (zero if empty); on exit x, y and z
  /// (m x k) hold the last iterate. Rows whose bounds are equal in every column are
  /// equality rows. rho carries over from the previous solve; K changes only when the
  /// equality pattern or rho changed.
  AdmmInfo solve(const Eigen::MatrixXd& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                 Eigen::MatrixXd& x, Eigen::MatrixXd& y, Eigen::MatrixXd& z);
  /// solve() without fetching the iterate: it stays where the kernels keep it, for the
  /// polish's steps below, until download(). `relaxed`, when not null, is the bounds' form
  /// the kernels start from (lower and upper must be its l and u).
  /// q and x may be device matrices (AdmmKernels::start); WarmStart::Kept starts from the
  /// iterate the last solve left (x and y then serve only before any solve).
  AdmmInfo iterate(const DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                   const RelaxedBounds* relaxed, const DeviceMatrix& x, const Eigen::MatrixXd& y,
                   WarmStart warm = WarmStart::Given);
  /// iterate() without an iteration: the kernels start from the warm starts and measure
  /// them, and K is not formed. Solved when the start meets the tolerances, else
  /// MaxIterationsReached with 0 iterations. The kernels' refinements (refineActiveSet)
  /// then start from it: an all-equality problem's polish needs no ADMM iterate before it (projective/
  /// BoxQp.h); an iterate() after them starts from the same point again.
  AdmmInfo load(const DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                const RelaxedBounds* relaxed, const DeviceMatrix& x, const Eigen::MatrixXd& y,
                WarmStart warm = WarmStart::Given);
  /// max |C x - centre| over all rows and columns of relaxed bounds (their centre; epsilon
  /// is not used), measured where the kernels keep the iterate: they are started at x (the
  /// next solve starts again), and a q, centre and flags that the next start shares are
  /// loaded for it already. For kernels that do not keep the iterate (no boundViolation),
  /// the host's product with `hostC()` (these kernels' C, asked for only then: its values
  /// may have to come from the device). NaN when C x is not finite.
  double violationAt(const DeviceMatrix& q, const RelaxedBounds& bounds, const DeviceMatrix& x,
                     const std::function<const SparseMatrix&()>& hostC);
  void download(Eigen::MatrixXd& x, Eigen::MatrixXd& y, Eigen::MatrixXd& z) { kernels_->download(x, y, z); }
  /// AdmmKernels::solution and centreDistance on the last solve's iterate.
  std::optional<DeviceMatrix> solution() { return kernels_->solution(); }
  std::optional<double> centreDistance(bool relaxedRows) { return kernels_->centreDistance(relaxedRows); }
  void downloadSolution(Eigen::MatrixXd& x, Eigen::MatrixXd* y) { kernels_->downloadSolution(x, y); }

  /// The same with the bounds as a relaxation (RelaxedBounds: centre m x k, one flag per
  /// row, epsilon finite and >= 0, else Error(Usage)), which the kernels form where they
  /// keep the iterate.
  AdmmInfo solve(const Eigen::MatrixXd& q, const RelaxedBounds& bounds, Eigen::MatrixXd& x, Eigen::MatrixXd& y,
                 Eigen::MatrixXd& z);

  /// New values of C on its pattern (a loop whose constraints change values only, as the
  /// projective global step's with each local step's scale factors): the next solve forms
  /// K again, keeping everything that depends on the pattern. Throws Error(Usage) when C's
  /// size or pattern (compressed) differs from the one given at construction.
  void setConstraintValues(const SparseMatrix& C);
  /// C's values as a scaling of its entries from now on (ConstraintScaling; checked against
  /// C's entry count, Error(Usage)), then new values by their scales: on the device one
  /// scale per corner crosses instead of C's values. Throws Error(Usage) for scales given
  /// before a scaling or of another count. Scales equal to the last call's change nothing
  /// (no kernel runs, nothing is copied to a device, K stays). `currentScales`, when not
  /// empty, are the scales C's present values were formed from (fillScaledValues): the
  /// first setConstraintScales with them changes nothing either.
  void setConstraintScaling(ConstraintScaling scaling, std::span<const double> currentScales = {});
  void setConstraintScales(std::span<const double> scales);
  /// The same with the scales a device matrix (#scales x 1): formed where the kernels keep C
  /// when the matrix lives there (AdmmKernels::setDeviceConstraintScales), nothing compared.
  void setConstraintScales(const DeviceMatrix& scales);

  /// AdmmKernels::refineActiveSet on the last solve's iterate; false when the kernels have
  /// none. The next solve forms K again.
  bool refineActiveSet(const ActiveSetRefinement& request, Eigen::MatrixXd& x, Eigen::MatrixXd& y,
                       ActiveSetRefinementInfo& info);
  /// AdmmKernels::findActiveSides, boundViolation and discardRefinement on the iterate.
  bool findActiveSides(std::vector<BoundSide>& sides) { return kernels_->findActiveSides(sides); }
  double boundViolation() { return kernels_->boundViolation(); }
  void discardRefinement();

  /// The rho the next solve starts at (by default the last solve's final rho): a caller
  /// rewinds it after a solve whose rho ran off (projective/GlobalStep.cpp). Throws
  /// Error(Usage) unless rho is finite and > 0.
  void setRho(double rho);

  const AdmmSettings& settings() const { return settings_; }
  /// The rho the next solve starts at.
  double rho() const { return rho_; }

 private:
  /// iterate() and load(): `iterations` false stops after the start's measurement.
  AdmmInfo run(const DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
               const RelaxedBounds* relaxed, const DeviceMatrix& x, const Eigen::MatrixXd& y, WarmStart warm,
               bool iterations);

  std::unique_ptr<AdmmKernels> kernels_;
  Eigen::Index n_;
  Eigen::Index m_;
  AdmmSettings settings_;
  double rho_;
  bool factored_ = false;
  std::vector<char> factoredEquality_;
  double factoredRho_ = 0.0;
  std::int32_t scaleCount_ = -1;  ///< Of the scaling given, -1 before one.
  /// The scales C's values were last formed from; empty when they were not (no scales
  /// yet, or values given by setConstraintValues).
  std::vector<double> scales_;
};

/// Whether A and B are compressed and have the same size and the same nonzero positions.
bool sameSparsityPattern(const SparseMatrix& A, const SparseMatrix& B);

/// The host kernels: the loop on the host, solving with `backend.createSpdSolver` (a prefactored
/// Cholesky on the CPU backend). The default of Backend::createAdmmSolver.
std::unique_ptr<AdmmKernels> createHostAdmmKernels(Backend& backend, const SparseMatrix& P, const SparseMatrix& C,
                                                   const AdmmSettings& settings);

}  // namespace plano::compute
