#pragma once
// OSQP-style ADMM for the convex quadratic programs of the global step (projective-maps
// paper, Eq. 4 with the ε relaxation of §4.2):
//
//   minimize  sum_c 1/2 x_c^T P x_c + q_c^T x_c   subject to  l_c <= C x_c <= u_c,
//
// for k independent columns x_c that share P (n x n, symmetric positive definite) and C
// (m x n) and differ in q, l and u. The iteration follows OSQP (Stellato et al. 2020):
// the only linear system is K = P + sigma I + C^T diag(rho) C, one solve for all k
// columns; rows with l = u get a 1e3 times stiffer rho, as in OSQP. rho adapts to the
// ratio of the residuals (K changes only when rho moves by more than
// `adaptiveRhoFactor`). The iteration itself is the backend's (Backend::createAdmmSolver,
// compute/Admm.h): on the CPU the Eigen loop with a prefactored Cholesky, on Vulkan the
// whole loop on the device. A converged (or solved-inaccurate) solution is then polished
// by re-solving with the active bounds as equalities, which removes the ADMM's residual
// tolerance from the answer: the active sets and the acceptance here, the refinements where
// the ADMM's kernels keep the iterate (compute::AdmmKernels::refineActiveSet: the device's),
// else here on the host.
//
// A problem whose rows are all equalities (l = u: the global step's ε = 0 attempts) needs
// no ADMM at all: the polish's solve with every row active is its exact solution, so it is
// solved that way directly where the backend factors K (BoxQpSettings::equalitySolve), and
// on the device from a loop's warm start. The ADMM took 30-50
// iterations there, each a solve with a K whose stiff equality rows made it the global
// step's dearest part, and ended in that same polish.
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "compute/Admm.h"
#include "compute/Backend.h"
#include "projective/ScaledConstraintMatrix.h"

namespace plano::projective {

/// How BoxQpSolver solves a problem whose rows are all equalities (l = u).
enum class EqualitySolve {
  /// The polish's method of multipliers from the warm starts, no ADMM. Its solution is
  /// accepted when every column meets the ADMM's primal tolerance; a residual that no
  /// refinement reduces and that carries OSQP's infeasibility certificate ends
  /// PrimalInfeasible; anything else (a factorization or inner solve that fails) falls
  /// back to the ADMM.
  Direct,
  Admm,  ///< The ADMM, then the polish, as for any other problem.
  /// Direct where the backend factors SPD matrices (Backend::factorsSpdMatrices). Where the
  /// ADMM's kernels keep the iterate (the device), the polish's method of multipliers runs
  /// alone, in place, from the start's multipliers (a loop's next exact step,
  /// WarmStart::Kept, or given ones) or from zero ones, and stands once its residual is near
  /// rounding (within BoxQpSettings::equalityPolishIterations refinements at the mild
  /// penalty, given up as soon as their contraction shows it would not get there, then at
  /// equalityPolishStiffRho); else (once per solver) the ADMM solves the step from the same
  /// start, and the solver's later exact steps. It saves the ADMM's K and its inversion:
  /// lavapipe deformations of the 8x8 / 10x10 grids, 36 iterations, 11.5 -> 8.1-8.5 s and
  /// 27.0 -> 18.4-19.0 s (warm steps). From zero multipliers (`BM_GlobalStep/vulkan`,
  /// 2026-12-07, lavapipe) on 256 / 1k / 4k faces 1 816 / 4 380 / 5 021 -> 909 / 1 598 /
  /// 2 007 PCG iterations, 5.8 / 47.5 / 197 -> 2.7 / 18.5 / 76 s. Until then those steps
  /// took the ADMM first: the mild refinements alone crawl there (C's soft modes), and a
  /// stiff system's PCG iterations from a cold start had grown fast with the mesh (a
  /// factored solve's penalty, 1e9: 1k faces did not converge within 10 000 iterations).
  /// The stiff phase goes on from where the mild one stopped, solving for its steps.
  Automatic,
};

/// The polish's penalty where its systems are factored: the method of multipliers then
/// converges in two or three refinements, and a backward-stable factorization leaves the
/// answer's directions that C does not fix accurate to rounding.
inline constexpr double kFactoredPolishRho = 1e9;
/// Its penalty where they are solved by PCG: there the residual b - K x, formed with K's
/// stiff rho C^T C part, is known only to about 1e-16 rho |x|, and that floor is the error
/// left in those directions. Measured on lavapipe, the 8x8 grid's ε = 0 global step against
/// its KKT solution (max entry error; PCG iterations of ADMM + polish): rho 1e9 6.4e-8
/// (7 637), 1e7 9.6e-10 (7 812), 1e6 1.3e-10 (6 680), 1e5 8.0e-12 (7 128, 7
/// refinements), 1e4 9.2e-13 (8 290, 16 refinements); 1e5 with the device polish's rounding
/// floor (vk::AdmmKernels::kPolishRoundingFloor) 1.1e-11 (5 629).
inline constexpr double kIterativePolishRho = 1e5;
/// The stiff penalty of the polish that solves an exact step alone on an iterative
/// backend (EqualitySolve::Automatic), where its refinements at kIterativePolishRho would
/// not reach rounding (compute::ActiveSetRefinement::stiffRho): they go on solving for
/// their steps, whose right-hand side leaves no rho-sized rounding, and the stiff penalty
/// makes the method of multipliers contract fast where the mild one crawls. Measured on
/// lavapipe, `BM_GlobalStep/vulkan/4096` from zero multipliers (64 mild refinements, 419
/// PCG iterations, then the stiff ones): 1e6 gives up after 76 (the ADMM then solves the
/// step), 1e7 62 refinements and 1 725 PCG iterations, 1e8 22 and 1 588, 1e9 15 and 3 931.
inline constexpr double kIterativeExactStepRho = 1e8;

/// The ADMM's settings (compute::AdmmSettings) and those of the final polish.
struct BoxQpSettings : compute::AdmmSettings {
  bool polish = true;
  int polishIterations = 30;         ///< Max method-of-multipliers refinements of the polish.
  /// Max refinements of the ADMM's polish where its kernels keep the iterate (the device,
  /// polishInPlace). More than polishIterations: there the refinements' solves are
  /// iterative, the penalty mild (kIterativePolishRho) and the contraction slow on larger
  /// meshes. Measured on lavapipe, a 48x48 grid's (2.3k faces) first deformation step: with
  /// 30 refinements the polish fell short of rounding and the mesh ended 5.6e-4 of the
  /// diagonal from the CPU's (max planarity 1.1e-3 % against 1.9e-12 %); with 200 it is
  /// 1.3e-8 from it (2.4e-8 %), for 8 072 -> 10 269 PCG iterations.
  int inPlacePolishIterations = 200;
  /// Max refinements of the polish that solves an exact step alone
  /// (EqualitySolve::Automatic on the device). More than polishIterations: falling short
  /// costs the ADMM and a second polish, and the polish's refinements are cheap ones there
  /// (loosely solved: compute::ActiveSetRefinement::farStart). Measured on lavapipe,
  /// a 16x16 grid's deformation (first row fixed, far corner moved): from the last step's
  /// multipliers (residual 5e-4) the polish is at 4e-10 after 30 refinements and at rounding
  /// (1e-14) after 60. On the 32x32 grid (1k faces) it stands after ~165 refinements
  /// (1.3e-3 -> 4.5e-13), 4 101 PCG iterations against 10 735 for the ADMM and its polish
  /// that solved the step when the cap was 60; on 48x48 (2.3k faces) it was given up either
  /// way (its contraction too slow), 477 PCG iterations later than with 60, until it went on
  /// at a stiff penalty instead (equalityPolishStiffRho).
  int equalityPolishIterations = 200;
  /// The stiff penalty at which that polish goes on where its refinements at polishRho
  /// would not reach rounding (compute::ActiveSetRefinement::stiffRho); 0: it gives up
  /// there, and the ADMM solves the step.
  double equalityPolishStiffRho = kIterativeExactStepRho;
  /// Penalty of the polish's equality system; 0 picks kFactoredPolishRho where the backend
  /// factors SPD matrices (Backend::factorsSpdMatrices), kIterativePolishRho where it iterates.
  double polishRho = 0.0;
  /// How an all-equality problem (every row l = u) is solved (EqualitySolve).
  EqualitySolve equalitySolve = EqualitySolve::Automatic;
  /// An all-equality problem solved by the ADMM (an iterative backend's ε = 0 attempts)
  /// starts from the iterate (x and the multipliers) and the rho the last solve ended at,
  /// where they stay (compute::WarmStart::Kept), when that solve was one too and succeeded:
  /// a local/global loop's next exact global step, whose rows are the same and whose
  /// targets moved little. Otherwise (and when off) it starts at the initial rho from the
  /// x and y given (zero where empty). The multipliers are the slow part of that method of
  /// multipliers: from zero, the modes that C barely constrains converge only at a rho far
  /// above the initial one. Measured on lavapipe, `plano --backend vulkan deform` of a 16x16
  /// grid (first row fixed, far corner moved by (0.1, 0.1, 0.3)), 36 iterations either way:
  /// ADMM iterations 730 -> 371, PCG iterations 101 040 -> 69 963, 305 -> 181 s; the mesh
  /// 5.6e-13 of the diagonal from the CPU's.
  bool warmStartEqualities = false;
  /// Return the multipliers y. A caller that never warm-starts from them turns this off:
  /// solve() then leaves y empty, and off a device they are not copied back.
  bool returnDuals = true;
};

enum class BoxQpStatus {
  Solved,               ///< Primal and dual residuals below their tolerances.
  PrimalInfeasible,     ///< An infeasibility certificate was found (no x satisfies the bounds).
  MaxIterationsReached, ///< Neither converged nor proven infeasible.
  NonFinite,            ///< NaN or Inf appeared in the iteration.
  Stalled,              ///< Neither converging nor certifying (compute::AdmmStatus::Stalled).
  SolvedInaccurate,     ///< Feasible, optimal only to a looser tolerance (compute::AdmmStatus::SolvedInaccurate).
};

const char* toString(BoxQpStatus status);

/// Solved or SolvedInaccurate: the solution is usable.
inline bool isSolved(BoxQpStatus status) {
  return status == BoxQpStatus::Solved || status == BoxQpStatus::SolvedInaccurate;
}

struct BoxQpInfo {
  BoxQpStatus status = BoxQpStatus::MaxIterationsReached;
  int iterations = 0;            ///< ADMM iterations.
  int factorizations = 0;        ///< Factorizations of K (1 + rho updates; a direct solve's: 1).
  /// Of the ADMM's solves with K (1 per direct solve, PCG iterations on the device) and,
  /// where the ADMM's kernels polish, of the polish's solves.
  long linearIterations = 0;
  double primalResidual = 0.0;   ///< ||C x - z||_inf (max over columns), after polishing.
  double dualResidual = 0.0;     ///< ||P x + q + C^T y||_inf before polishing.
  double maxBoundViolation = 0.0;  ///< max(l - Cx, Cx - u, 0) over all rows and columns.
  double rho = 0.0;              ///< Final rho.
  bool polished = false;         ///< The polished solution was accepted.
  /// Solved (or found infeasible) by the direct equality solve, without ADMM iterations
  /// (EqualitySolve::Direct).
  bool direct = false;
  /// Method-of-multipliers refinements of the polish or of the direct equality solve, one
  /// solve each (columns that share an active set share them).
  int polishRefinements = 0;
};

/// Whether a solve returned its warm start as the solution: no ADMM iteration and no
/// refinement of a direct equality solve.
inline bool startWasOptimal(const BoxQpInfo& info) { return info.iterations == 0 && info.polishRefinements == 0; }

class BoxQpSolver {
 public:
  /// Precompute: keeps P (n x n) and C (m x n) and creates the backend's ADMM solver; K
  /// is formed on the first solve.
  BoxQpSolver(compute::Backend& backend, compute::SparseMatrix P, compute::SparseMatrix C,
              const BoxQpSettings& settings = {});

  /// Solve for k columns at once.
  ///   q     in: n x k linear terms.
  ///   lower, upper  in: m x k bounds (lower <= upper; equal for equality rows).
  ///   x     in/out: n x k, warm start on entry (zero if empty), solution on exit.
  ///   y     in/out: m x k dual variables, warm start on entry (zero if empty); empty on exit
  ///         without BoxQpSettings::returnDuals.
  /// Rows whose bounds are equal in every column are equality rows. K changes when the
  /// equality pattern or rho changed since the last solve.
  /// q may be a device matrix (compute::DeviceMatrix): the ADMM binds it where it runs,
  /// the host steps (a direct solve, the host's polish) read its values.
  BoxQpInfo solve(const compute::DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                  Eigen::MatrixXd& x, Eigen::MatrixXd& y);

  /// The same with the bounds as a relaxation (compute::RelaxedBounds: an ε schedule's
  /// attempts), which the ADMM forms where it runs.
  BoxQpInfo solve(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds, Eigen::MatrixXd& x,
                  Eigen::MatrixXd& y);
  /// The same with x's warm start given apart (n x k, possibly a device matrix: the global
  /// step's targets, whose negation is q); x receives the solution.
  BoxQpInfo solve(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                  const compute::DeviceMatrix& start, Eigen::MatrixXd& x, Eigen::MatrixXd& y);

  /// The same with the solution left where the ADMM keeps its iterate (a device matrix
  /// there; host values where the ADMM runs on the host or a host step finished the solve).
  /// Needs BoxQpSettings::returnDuals off to leave it on a device.
  BoxQpInfo solve(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                  const compute::DeviceMatrix& start, compute::DeviceMatrix& x);
  /// max |C x - bounds.centre| over all rows (`relaxedRows`) or over the rows not relaxed,
  /// for the x the last solve gave: measured where the ADMM keeps it when x is a device
  /// matrix of that solve, else on the host. NaN when C x is not finite.
  double centreDistance(const compute::DeviceMatrix& x, const compute::RelaxedBounds& bounds, bool relaxedRows);

  /// max |C x - bounds.centre| (compute::AdmmSolver::violationAt: where the ADMM runs, which
  /// then holds q and the bounds' centre for the next solve).
  double violationAt(const compute::DeviceMatrix& q, const compute::RelaxedBounds& bounds,
                     const compute::DeviceMatrix& x);

  /// C's values as a scaling of its entries from now on (compute::AdmmSolver::
  /// setConstraintScaling), then new values by their scales: the ADMM forms them where it
  /// runs, and C (its values for those scales) serves the polish here. `currentScales`:
  /// as compute::AdmmSolver::setConstraintScaling's.
  void setConstraintScaling(const compute::ConstraintScaling& scaling, std::span<const double> currentScales = {});
  void setScaledConstraintValues(const compute::SparseMatrix& C, std::span<const double> scales);
  /// New values by their scales (#scales x 1) alone, which may stay on the device that
  /// computed them (compute::AdmmSolver::setConstraintScales); C's values here are formed
  /// from them only when a step on the host needs them (their copy then comes over).
  void setConstraintScales(const compute::DeviceMatrix& scales);
  /// The rho the next solve starts at (compute::AdmmSolver::rho, setRho).
  double rho() const { return admm_->rho(); }
  void setRho(double rho) { admm_->setRho(rho); }

  const BoxQpSettings& settings() const { return settings_; }

 private:
  /// What solveActiveSet did.
  struct ActiveSetSolve {
    bool factored = false;         ///< Its matrix could be factored (or set up) at all.
    bool newlyFactored = false;    ///< Factored (or set up) for this solve, not the kept one.
    bool solvesConverged = true;   ///< Every inner solve reached its tolerance.
    int refinements = 0;
  };

  /// The solves': `relaxed` (when not null) is the bounds' form to hand the ADMM, `start`
  /// (when not null) x's warm start (else x on entry).
  BoxQpInfo solve(const compute::DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                  const compute::RelaxedBounds* relaxed, const compute::DeviceMatrix* start, Eigen::MatrixXd& x,
                  Eigen::MatrixXd& y, compute::DeviceMatrix* kept = nullptr);
  /// The solution's fetch (`fetch`: from the ADMM's kernels, into `kept` where they keep it
  /// and the caller asks so, else into x), its bound violation, and whether the kernels hold
  /// an all-equality solution for the next warm start.
  BoxQpInfo finishSolve(BoxQpInfo& info, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                        bool allEqualities, bool fetch, Eigen::MatrixXd& x, Eigen::MatrixXd& y,
                        compute::DeviceMatrix* kept);
  /// An all-equality problem where the ADMM's kernels keep the iterate (EqualitySolve::
  /// Automatic on the device) from a start with multipliers: the polish's method of
  /// multipliers from the start `loaded` (compute::AdmmSolver::load), with no ADMM
  /// iteration. True, with info, when the start was optimal or the polished residual is near
  /// rounding (kEqualityPolishResidual in the .cpp); else false, the loaded start again the
  /// iterate, and info.linearIterations and polishRefinements the work spent.
  bool solveEqualitiesInPlace(const compute::AdmmInfo& loaded, const Eigen::MatrixXd& bounds, BoxQpInfo& info);
  /// How polishInPlace refines each active set.
  struct InPlacePolish {
    int maxRefinements;  ///< Per set.
    /// > 0: give up a set's refinements that would not reach it
    /// (compute::ActiveSetRefinement::reach).
    double reach = 0.0;
    bool farStart = false;  ///< compute::ActiveSetRefinement::farStart.
    /// A set's refinements stop at a residual of `goal` or at rounding, whichever is larger.
    double goal = 0.0;
    double stiffRho = 0.0;  ///< compute::ActiveSetRefinement::stiffRho.
  };
  /// The polish where the ADMM's kernels keep the iterate, when they find its active sets
  /// there (compute::AdmmKernels::findActiveSides): one refinement per distinct set, merged
  /// by the kernels; only the sides found (a byte per four rows and columns), the active
  /// flags of each set and a few norms cross, and the iterate stays for the final download.
  /// Sets info.polished and polishRefinements; false when the kernels cannot (iterate
  /// untouched: polish() then works from the downloaded iterate). `how` says how far and
  /// at which penalties.
  bool polishInPlace(const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper, BoxQpInfo& info,
                     const InPlacePolish& how);
  bool polish(const Eigen::MatrixXd& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
              const Eigen::MatrixXd& z, Eigen::MatrixXd& x, Eigen::MatrixXd& y, int& refinements);
  /// The direct solve of an all-equality problem (EqualitySolve::Direct) from
  /// the warm starts; false when it falls back to the ADMM (x and y then untouched).
  bool solveEqualities(const Eigen::MatrixXd& q, const Eigen::MatrixXd& d, Eigen::MatrixXd& x, Eigen::MatrixXd& y,
                       BoxQpInfo& info);
  /// Method of multipliers on min 1/2 x'Px + q'x s.t. C_A x = b for `columns`, which
  /// share the active rows `active` (C_A: those rows of C, b: those rows of `targets`):
  /// x's and y's columns are the warm starts on entry and the result on exit (y: the
  /// active rows' multipliers, zero on the others).
  /// The refinements solve for the new points (warm-started at x: the polish, near the
  /// solution) or for the steps to them (a cold start: the direct solve); see the .cpp.
  enum class Refinement { ForPoints, ForSteps };
  ActiveSetSolve solveActiveSet(const std::vector<char>& active, const std::vector<Eigen::Index>& columns,
                                const Eigen::MatrixXd& q, const Eigen::MatrixXd& targets, Refinement form,
                                Eigen::MatrixXd& x, Eigen::MatrixXd& y);

  /// C with its values for the last scales given (formed from pendingScales_ first).
  const compute::SparseMatrix& hostC();

  compute::Backend& backend_;
  BoxQpSettings settings_;
  compute::SparseMatrix P_;
  compute::SparseMatrix C_;  ///< Its values are stale while pendingScales_ holds scales.
  compute::ConstraintScaling scaling_;
  std::optional<compute::DeviceMatrix> pendingScales_;
  std::unique_ptr<compute::AdmmSolver> admm_;
  /// The solver of the system with every row active (each direct equality solve's, an
  /// all-equality polish's) where the backend factors: its pattern is C's, fixed for this
  /// object's lifetime, so later systems refactor it, keeping what depends on the pattern
  /// (CHOLMOD's ordering and symbolic analysis).
  std::unique_ptr<compute::SpdSolver> allRowsSolver_;
  /// allRowsSolver_ holds the factorization of C_'s present values: a next all-rows solve
  /// reuses it as it is (no refactorization). False after new values of C.
  bool allRowsCurrent_ = false;
  /// The last solve was an all-equality problem that the ADMM solved (or solved
  /// inaccurately): its iterate, where the ADMM keeps it, starts the next such solve
  /// (BoxQpSettings::warmStartEqualities).
  bool equalityIterateHeld_ = false;
  /// An all-equality polish with no ADMM before it (solveEqualitiesInPlace) fell short of
  /// rounding once: this problem's soft modes need more refinements than the polish runs,
  /// so its later exact steps go to the ADMM at once instead of paying for the polish twice
  /// (256-face deformation steps on lavapipe: 2 020 -> 3 262 PCG iterations when each
  /// tried it).
  bool equalityPolishFellShort_ = false;
};

/// The solver of a sequence of QPs whose C keeps one sparsity pattern (a loop's global
/// steps: C's values follow each local step's scale factors, its pattern the topology):
/// created by the first call, given C's new scales by later ones (C, filled for `scales`,
/// must be their values), so that everything it built for the pattern is kept (on the
/// device: buffers, pipelines, K's pattern, the multigrid's aggregates) and rho carries
/// over from one problem to the next (they are alike). `settings` is used on creation only.
BoxQpSolver& keptSolver(std::unique_ptr<BoxQpSolver>& kept, compute::Backend& backend, const compute::SparseMatrix& P,
                        const ScaledConstraintMatrix& C, std::span<const double> scales, const BoxQpSettings& settings);
/// keptSolver with C's new scales alone, which may stay on the device that computed them
/// (BoxQpSolver::setConstraintScales; C need not be filled for them).
BoxQpSolver& keptSolver(std::unique_ptr<BoxQpSolver>& kept, compute::Backend& backend, const compute::SparseMatrix& P,
                        const ScaledConstraintMatrix& C, const compute::DeviceMatrix& scales,
                        const BoxQpSettings& settings);

}  // namespace plano::projective
