#include "projective/BoxQp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "support/CpuForwardingBackend.h"

namespace plano::projective {
namespace {

/// A random QP with equality rows C x = d that some x0 satisfies: P = I + B B^T / n.
struct EqualityQp {
  compute::SparseMatrix P, C;
  Eigen::MatrixXd q, d;
};

EqualityQp consistentEqualityQp(Eigen::Index n, Eigen::Index m, Eigen::Index k, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const auto randomMatrix = [&](Eigen::Index rows, Eigen::Index cols) {
    Eigen::MatrixXd M(rows, cols);
    for (Eigen::Index i = 0; i < M.size(); ++i) M.data()[i] = uniform(random);
    return M;
  };
  const Eigen::MatrixXd B = randomMatrix(n, n);
  const Eigen::MatrixXd dense = Eigen::MatrixXd::Identity(n, n) + B * B.transpose() / static_cast<double>(n);
  EqualityQp qp;
  qp.P = dense.sparseView();
  qp.C = randomMatrix(m, n).sparseView();
  qp.C.makeCompressed();
  qp.q = randomMatrix(n, k);
  qp.d = qp.C * randomMatrix(n, k);
  return qp;
}

/// The CPU reference, but claiming iterative solves (as the Vulkan backend).
class IterativeClaimingBackend : public test::CpuForwardingBackend {
 public:
  std::string name() const override { return "cpu, claiming iterative solves"; }
  bool factorsSpdMatrices() const override { return false; }
};

/// qp's equalities (l = u = d) on a new solver of `backend`.
BoxQpInfo solveOnNewSolver(compute::Backend& backend, const EqualityQp& qp, const BoxQpSettings& settings,
                           Eigen::MatrixXd& x, Eigen::MatrixXd& y) {
  BoxQpSolver solver(backend, qp.P, qp.C, settings);
  return solver.solve(qp.q, qp.d, qp.d, x, y);
}

TEST(BoxQp, AllEqualityProblemIsSolvedDirectlyWithTheAdmmSolution) {
  const EqualityQp qp = consistentEqualityQp(12, 5, 3, 7);
  compute::CpuBackend backend;
  BoxQpSettings settings;
  settings.equalitySolve = EqualitySolve::Admm;
  Eigen::MatrixXd xAdmm, yAdmm;
  const BoxQpInfo admmInfo = solveOnNewSolver(backend, qp, settings, xAdmm, yAdmm);
  ASSERT_EQ(admmInfo.status, BoxQpStatus::Solved);
  EXPECT_GT(admmInfo.iterations, 0);
  EXPECT_FALSE(admmInfo.direct);

  settings.equalitySolve = EqualitySolve::Direct;
  Eigen::MatrixXd x, y;
  const BoxQpInfo info = solveOnNewSolver(backend, qp, settings, x, y);
  ASSERT_EQ(info.status, BoxQpStatus::Solved);
  EXPECT_TRUE(info.direct);
  EXPECT_EQ(info.iterations, 0);
  EXPECT_EQ(info.factorizations, 1);
  EXPECT_GE(info.polishRefinements, 1);
  EXPECT_LE(info.polishRefinements, settings.polishIterations);
  EXPECT_LT((qp.C * x - qp.d).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((x - xAdmm).cwiseAbs().maxCoeff(), 1e-8);
  // The multipliers make the point stationary, P x + q + C^T y = 0, to the rounding that
  // the penalty amplifies in their updates (rhoP = 1e9 times residuals of ~1e-15).
  EXPECT_LT((qp.P * x + qp.q + qp.C.transpose() * y).cwiseAbs().maxCoeff(), 1e-5);
}

TEST(BoxQp, AWarmStartThatSolvesTheProblemComesBackWithoutRefinements) {
  const EqualityQp qp = consistentEqualityQp(10, 4, 2, 11);
  compute::CpuBackend backend;
  BoxQpSolver solver(backend, qp.P, qp.C);
  Eigen::MatrixXd x, y;
  ASSERT_EQ(solver.solve(qp.q, qp.d, qp.d, x, y).status, BoxQpStatus::Solved);
  const Eigen::MatrixXd xSolved = x, ySolved = y;
  const BoxQpInfo again = solver.solve(qp.q, qp.d, qp.d, x, y);
  EXPECT_EQ(again.status, BoxQpStatus::Solved);
  EXPECT_TRUE(startWasOptimal(again));
  EXPECT_EQ(x, xSolved);
  EXPECT_EQ(y, ySolved);
}

TEST(BoxQp, InconsistentEqualitiesAreCertifiedInfeasibleWithoutAdmmIterations) {
  // Rows 0 and 1 ask x0 = 0 and x0 = 1.
  EqualityQp qp = consistentEqualityQp(6, 3, 1, 3);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(3, 6);
  C(0, 0) = 1.0;
  C(1, 0) = 1.0;
  C(2, 3) = 1.0;
  qp.C = C.sparseView();
  qp.C.makeCompressed();
  Eigen::MatrixXd d(3, 1);
  d << 0.0, 1.0, 0.5;
  compute::CpuBackend backend;
  BoxQpSolver solver(backend, qp.P, qp.C);
  const Eigen::MatrixXd xStart = Eigen::MatrixXd::Constant(6, 1, 0.25);
  Eigen::MatrixXd x = xStart, y;
  const BoxQpInfo info = solver.solve(qp.q, d, d, x, y);
  EXPECT_EQ(info.status, BoxQpStatus::PrimalInfeasible);
  EXPECT_TRUE(info.direct);
  EXPECT_EQ(info.iterations, 0);
  EXPECT_LE(info.polishRefinements, BoxQpSettings{}.polishIterations);
  EXPECT_EQ(x, xStart);  // the warm starts stay for the relaxed attempts
  EXPECT_EQ(y.size(), 0);
}

TEST(BoxQp, AutomaticSolvesDirectlyOnlyWhereTheBackendFactors) {
  const EqualityQp qp = consistentEqualityQp(12, 5, 3, 5);
  IterativeClaimingBackend iterative;
  Eigen::MatrixXd x, y;
  const BoxQpInfo info = solveOnNewSolver(iterative, qp, {}, x, y);
  EXPECT_EQ(info.status, BoxQpStatus::Solved);
  EXPECT_FALSE(info.direct);
  EXPECT_GT(info.iterations, 0);
}

TEST(BoxQp, AnAllEqualityAdmmSolveStartsAtTheInitialRhoNotTheCarriedOne) {
  // A carried rho raised by earlier stiff solves made the device's inner solves stiffer
  // without saving ADMM iterations: such a solve starts where a fresh solver would.
  const EqualityQp qp = consistentEqualityQp(12, 5, 3, 13);
  compute::CpuBackend backend;
  BoxQpSettings settings;
  settings.equalitySolve = EqualitySolve::Admm;
  Eigen::MatrixXd xFresh, yFresh;
  const BoxQpInfo freshInfo = solveOnNewSolver(backend, qp, settings, xFresh, yFresh);
  ASSERT_EQ(freshInfo.status, BoxQpStatus::Solved);

  BoxQpSolver carried(backend, qp.P, qp.C, settings);
  carried.setRho(1e4);
  Eigen::MatrixXd x, y;
  const BoxQpInfo info = carried.solve(qp.q, qp.d, qp.d, x, y);
  EXPECT_EQ(info.status, BoxQpStatus::Solved);
  EXPECT_EQ(info.iterations, freshInfo.iterations);
  EXPECT_EQ(info.rho, freshInfo.rho);
  EXPECT_LT((x - xFresh).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(BoxQp, WarmStartedEqualitySolvesStartFromTheLastSolvedOnesIterateAndRho) {
  // A loop's next exact step: the same rows, a nearby q. Started from the last solve's
  // iterate (held by the ADMM's kernels) and rho, it needs fewer iterations to the same
  // solution (measured 7 against 12); after a solve with an inequality row, or without the
  // setting, it starts at the initial rho from the x and y given, as a fresh solver would.
  const EqualityQp qp = consistentEqualityQp(12, 5, 3, 13);
  const Eigen::MatrixXd nearby = qp.q * 1.01;
  compute::CpuBackend backend;
  BoxQpSettings settings;
  settings.equalitySolve = EqualitySolve::Admm;
  settings.checkInterval = 1;
  Eigen::MatrixXd xFresh, yFresh;
  const BoxQpInfo fresh = solveOnNewSolver(backend, {qp.P, qp.C, nearby, qp.d}, settings, xFresh, yFresh);
  ASSERT_EQ(fresh.status, BoxQpStatus::Solved);

  for (const bool warm : {false, true}) {
    SCOPED_TRACE(warm ? "warm" : "cold");
    settings.warmStartEqualities = warm;
    BoxQpSolver solver(backend, qp.P, qp.C, settings);
    Eigen::MatrixXd x, y;
    const BoxQpInfo first = solver.solve(qp.q, qp.d, qp.d, x, y);
    ASSERT_EQ(first.status, BoxQpStatus::Solved);
    Eigen::MatrixXd xNext, yNext;
    const BoxQpInfo next = solver.solve(nearby, qp.d, qp.d, xNext, yNext);
    ASSERT_EQ(next.status, BoxQpStatus::Solved);
    EXPECT_LT((xNext - xFresh).cwiseAbs().maxCoeff(), 1e-8);
    if (warm) {
      EXPECT_LE(10 * next.iterations, 6 * fresh.iterations);
    } else {
      EXPECT_EQ(next.iterations, fresh.iterations);
    }

    // A box row in between: the next exact solve starts as a fresh one.
    Eigen::MatrixXd lower = qp.d, upper = qp.d;
    lower.row(0).array() -= 10.0;
    upper.row(0).array() += 10.0;
    Eigen::MatrixXd xBox, yBox;
    ASSERT_TRUE(isSolved(solver.solve(qp.q, lower, upper, xBox, yBox).status));
    Eigen::MatrixXd xAfter, yAfter;
    const BoxQpInfo after = solver.solve(nearby, qp.d, qp.d, xAfter, yAfter);
    EXPECT_EQ(after.iterations, fresh.iterations);
    EXPECT_LT((xAfter - xFresh).cwiseAbs().maxCoeff(), 1e-8);
  }
}

TEST(BoxQp, AnAllEqualityAdmmSolveIsNotOverRelaxed) {
  // Its rows are stiff (rho c^2 >> 1 at the equality rows' rho): the iteration, the method
  // of multipliers there, shrinks their error by |1 - alpha| per iteration, 0.3 with
  // AdmmSettings::equalityRelaxation against 0.6 with OSQP's alpha (measured: 12 and 26
  // iterations).
  const EqualityQp qp = consistentEqualityQp(12, 5, 3, 17);
  compute::CpuBackend backend;
  BoxQpSettings settings;
  settings.equalitySolve = EqualitySolve::Admm;
  settings.checkInterval = 1;
  settings.polish = false;
  Eigen::MatrixXd x, y;
  const BoxQpInfo info = solveOnNewSolver(backend, qp, settings, x, y);
  ASSERT_EQ(info.status, BoxQpStatus::Solved);

  BoxQpSettings overRelaxed = settings;
  overRelaxed.equalityRelaxation = overRelaxed.relaxation;
  Eigen::MatrixXd xOver, yOver;
  const BoxQpInfo overInfo = solveOnNewSolver(backend, qp, overRelaxed, xOver, yOver);
  ASSERT_EQ(overInfo.status, BoxQpStatus::Solved);
  EXPECT_LT(2 * info.iterations, overInfo.iterations);
  EXPECT_LT((x - xOver).cwiseAbs().maxCoeff(), 1e-5);

  for (const double alpha : {0.0, 2.0, std::nan("")}) {
    BoxQpSettings wrong = settings;
    wrong.equalityRelaxation = alpha;
    EXPECT_THROW(solveOnNewSolver(backend, qp, wrong, x, y), Error) << alpha;
  }
}

TEST(BoxQp, AProblemWithAnInequalityRowKeepsTheOverRelaxation) {
  // One row of the equality problem widened to a box that it meets loosely: an OSQP
  // problem like any other, iterated with AdmmSettings::relaxation whatever
  // equalityRelaxation says.
  const EqualityQp qp = consistentEqualityQp(12, 5, 3, 17);
  Eigen::MatrixXd lower = qp.d, upper = qp.d;
  lower.row(0).array() -= 10.0;
  upper.row(0).array() += 10.0;
  compute::CpuBackend backend;
  BoxQpSettings settings;
  settings.checkInterval = 1;
  settings.polish = false;
  std::vector<int> iterations;
  for (const double alpha : {1.0, 1.6}) {
    settings.equalityRelaxation = alpha;
    BoxQpSolver solver(backend, qp.P, qp.C, settings);
    Eigen::MatrixXd x, y;
    const BoxQpInfo info = solver.solve(qp.q, lower, upper, x, y);
    ASSERT_EQ(info.status, BoxQpStatus::Solved);
    iterations.push_back(info.iterations);
  }
  EXPECT_EQ(iterations[0], iterations[1]);
}

/// The CPU reference, counting the SPD solvers it is asked for; with `failFirst`, the
/// first one (the direct solve's) cannot be factored.
class CountingBackend : public test::CpuForwardingBackend {
 public:
  explicit CountingBackend(bool failFirst = false) : failFirst_(failFirst) {}
  std::string name() const override { return "cpu, counting SPD solvers"; }
  std::unique_ptr<compute::SpdSolver> createSpdSolver(const compute::SparseMatrix& A,
                                                      const compute::LinearSolverSettings& settings) override {
    if (created++ == 0 && failFirst_) throwNumerical("SPD solver: Cholesky factorization failed (simulated)");
    return cpu_.createSpdSolver(A, settings);
  }
  int created = 0;

 private:
  bool failFirst_;
};

TEST(BoxQp, DirectSolvesOfOneSolverFactorOnePatternOnce) {
  // Each direct solve's system has C's pattern: the first solver is kept and refactored
  // (CHOLMOD keeps its ordering and symbolic analysis), with the same solutions.
  const EqualityQp qp = consistentEqualityQp(12, 5, 3, 17);
  CountingBackend counting;
  BoxQpSolver kept(counting, qp.P, qp.C);
  Eigen::MatrixXd x, y;
  ASSERT_EQ(kept.solve(qp.q, qp.d, qp.d, x, y).status, BoxQpStatus::Solved);
  EXPECT_EQ(counting.created, 1);
  const Eigen::MatrixXd d2 = 2.0 * qp.d;
  const Eigen::MatrixXd q2 = -qp.q;
  Eigen::MatrixXd x2, y2;
  ASSERT_EQ(kept.solve(q2, d2, d2, x2, y2).status, BoxQpStatus::Solved);
  EXPECT_EQ(counting.created, 1);

  compute::CpuBackend cpu;
  BoxQpSolver fresh(cpu, qp.P, qp.C);
  Eigen::MatrixXd xFresh, yFresh;
  ASSERT_EQ(fresh.solve(q2, d2, d2, xFresh, yFresh).status, BoxQpStatus::Solved);
  EXPECT_LT((x2 - xFresh).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(BoxQp, DirectSolvesWithUnchangedConstraintValuesReuseTheFactorization) {
  // A rigid deformation's global steps give C the same values step after step: the kept
  // factorization of K = P + sigma I + rhoP C^T C serves them as it is; new values factor.
  const EqualityQp qp = consistentEqualityQp(12, 5, 3, 23);
  compute::ConstraintScaling scaling;
  scaling.scaleCount = 3;
  const auto entries = static_cast<std::size_t>(qp.C.nonZeros());
  scaling.coefficients.assign(qp.C.valuePtr(), qp.C.valuePtr() + entries);
  for (std::size_t e = 0; e < entries; ++e) scaling.scaleOf.push_back(static_cast<std::int32_t>(e % 3));
  const std::vector<double> ones(3, 1.0);
  compute::CpuBackend cpu;
  BoxQpSolver kept(cpu, qp.P, qp.C);
  kept.setConstraintScaling(scaling, ones);
  Eigen::MatrixXd x, y;
  const BoxQpInfo first = kept.solve(qp.q, qp.d, qp.d, x, y);
  ASSERT_EQ(first.status, BoxQpStatus::Solved);
  EXPECT_EQ(first.factorizations, 1);

  const Eigen::MatrixXd q2 = -qp.q;
  kept.setScaledConstraintValues(qp.C, ones);
  Eigen::MatrixXd x2, y2;
  const BoxQpInfo again = kept.solve(q2, qp.d, qp.d, x2, y2);
  ASSERT_EQ(again.status, BoxQpStatus::Solved);
  EXPECT_TRUE(again.direct);
  EXPECT_EQ(again.factorizations, 0);
  BoxQpSolver fresh(cpu, qp.P, qp.C);
  Eigen::MatrixXd xFresh, yFresh;
  ASSERT_EQ(fresh.solve(q2, qp.d, qp.d, xFresh, yFresh).status, BoxQpStatus::Solved);
  EXPECT_LT((x2 - xFresh).cwiseAbs().maxCoeff(), 1e-12);

  const std::vector<double> other{0.5, 1.25, 2.0};
  compute::SparseMatrix C2 = qp.C;
  compute::fillScaledValues(scaling, other, C2.valuePtr());
  const Eigen::MatrixXd d2 = C2 * x;  // consistent for the new C
  kept.setScaledConstraintValues(C2, other);
  Eigen::MatrixXd x3, y3;
  const BoxQpInfo changed = kept.solve(qp.q, d2, d2, x3, y3);
  ASSERT_EQ(changed.status, BoxQpStatus::Solved);
  EXPECT_EQ(changed.factorizations, 1);
  BoxQpSolver freshChanged(cpu, qp.P, C2);
  Eigen::MatrixXd x4, y4;
  ASSERT_EQ(freshChanged.solve(qp.q, d2, d2, x4, y4).status, BoxQpStatus::Solved);
  EXPECT_LT((x3 - x4).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((C2 * x3 - d2).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(BoxQp, ADirectSolveThatCannotFactorFallsBackToTheAdmm) {
  const EqualityQp qp = consistentEqualityQp(12, 5, 3, 19);
  CountingBackend failing(/*failFirst=*/true);
  Eigen::MatrixXd x, y;
  const BoxQpInfo info = solveOnNewSolver(failing, qp, {}, x, y);
  EXPECT_EQ(info.status, BoxQpStatus::Solved);
  EXPECT_FALSE(info.direct);
  EXPECT_GT(info.iterations, 0);
  EXPECT_GE(failing.created, 2);
  EXPECT_LT((qp.C * x - qp.d).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(BoxQp, ADirectSolveWhoseFactorCannotFitIsRefusedWithoutAnAdmmAttempt) {
  // The ADMM's K has the same pattern: a fallback would only be refused again, later.
  const EqualityQp qp = consistentEqualityQp(12, 5, 3, 19);
  CountingBackend counting;
  BoxQpSettings settings;
  settings.linearSolver.memoryLimitBytes = 64;  // bytes: less than any factor of 12 rows
  Eigen::MatrixXd x, y;
  EXPECT_THROW(solveOnNewSolver(counting, qp, settings, x, y), OutOfMemory);
  EXPECT_EQ(counting.created, 1);
}

TEST(BoxQp, ProblemsWithInequalityRowsTakeTheAdmmEvenWhenDirectIsAsked) {
  const EqualityQp qp = consistentEqualityQp(12, 5, 2, 9);
  Eigen::MatrixXd upper = qp.d;
  upper.row(2).array() += 0.1;  // one relaxed row
  BoxQpSettings settings;
  settings.equalitySolve = EqualitySolve::Direct;
  compute::CpuBackend backend;
  BoxQpSolver solver(backend, qp.P, qp.C, settings);
  Eigen::MatrixXd x, y;
  const BoxQpInfo info = solver.solve(qp.q, qp.d, upper, x, y);
  EXPECT_EQ(info.status, BoxQpStatus::Solved);
  EXPECT_FALSE(info.direct);
  EXPECT_GT(info.iterations, 0);
}

TEST(BoxQp, AnAdmmWarmStartThatMeetsTheTolerancesFactorsNothing) {
  const EqualityQp qp = consistentEqualityQp(12, 5, 2, 13);
  const Eigen::MatrixXd lower = qp.d.array() - 0.1, upper = qp.d.array() + 0.1;  // every row relaxed
  compute::CpuBackend backend;
  BoxQpSolver solved(backend, qp.P, qp.C);
  Eigen::MatrixXd x, y;
  const BoxQpInfo first = solved.solve(qp.q, lower, upper, x, y);
  ASSERT_EQ(first.status, BoxQpStatus::Solved);
  ASSERT_GT(first.iterations, 0);
  EXPECT_GE(first.factorizations, 1);
  // A new solver (nothing factored yet) started at that solution: converged at the first
  // check, so K is never formed (on a 1M-face mesh, CHOLMOD's factorization of it alone took
  // most of a PQ subdivision level whose targets were already compatible).
  BoxQpSolver fresh(backend, qp.P, qp.C);
  const Eigen::MatrixXd xSolved = x;
  const BoxQpInfo again = fresh.solve(qp.q, lower, upper, x, y);
  EXPECT_EQ(again.status, BoxQpStatus::Solved);
  EXPECT_EQ(again.iterations, 0);
  EXPECT_EQ(again.factorizations, 0);
  EXPECT_LT((x - xSolved).cwiseAbs().maxCoeff(), 1e-12);
  // A start that needs iterations still forms K.
  Eigen::MatrixXd xCold, yCold;
  const BoxQpInfo cold = fresh.solve(qp.q, lower, upper, xCold, yCold);
  EXPECT_EQ(cold.status, BoxQpStatus::Solved);
  EXPECT_GT(cold.iterations, 0);
  EXPECT_GE(cold.factorizations, 1);
}

TEST(BoxQp, TheAdmmReportsEachConvergenceCheckToItsCallback) {
  const EqualityQp qp = consistentEqualityQp(12, 5, 2, 17);
  const Eigen::MatrixXd lower = qp.d.array() - 0.1, upper = qp.d.array() + 0.1;
  std::vector<compute::AdmmCheck> checks;
  BoxQpSettings settings;
  settings.polish = false;
  settings.onCheck = [&](const compute::AdmmCheck& check) { checks.push_back(check); };
  compute::CpuBackend backend;
  BoxQpSolver solver(backend, qp.P, qp.C, settings);
  Eigen::MatrixXd x, y;
  const BoxQpInfo info = solver.solve(qp.q, lower, upper, x, y);
  ASSERT_EQ(info.status, BoxQpStatus::Solved);
  ASSERT_GT(info.iterations, 0);
  ASSERT_EQ(checks.size(), static_cast<std::size_t>(info.iterations / settings.checkInterval));
  for (std::size_t i = 0; i < checks.size(); ++i) {
    EXPECT_EQ(checks[i].iterations, static_cast<int>(i + 1) * settings.checkInterval);
    EXPECT_GT(checks[i].primalTolerance, 0.0);
    EXPECT_GT(checks[i].dualTolerance, 0.0);
    EXPECT_GT(checks[i].rho, 0.0);
    EXPECT_EQ(checks[i].linearIterations, checks[i].iterations) << "one factored solve per ADMM iteration";
  }
  // The last check is the converged one, with the residuals the solve reports.
  EXPECT_EQ(checks.back().primalResidual, info.primalResidual);
  EXPECT_EQ(checks.back().dualResidual, info.dualResidual);
  EXPECT_EQ(checks.back().linearIterations, info.linearIterations);
  EXPECT_LE(checks.back().primalResidual, checks.back().primalTolerance);
  EXPECT_LE(checks.back().dualResidual, checks.back().dualTolerance);
}

TEST(BoxQp, ADualToleranceScaleLoosensOnlyTheDualTolerance) {
  // rho held high: the primal residual converges first and the dual one decides the stop.
  const EqualityQp qp = consistentEqualityQp(40, 13, 2, 2);
  const Eigen::MatrixXd lower = qp.d.array() - 0.01, upper = qp.d.array() + 0.01;
  compute::CpuBackend backend;
  const auto solveWithScale = [&](double scale, std::vector<compute::AdmmCheck>& checks) {
    BoxQpSettings settings;
    settings.polish = false;
    settings.adaptiveRho = false;
    settings.rho = 100.0;
    settings.dualToleranceScale = scale;
    settings.onCheck = [&](const compute::AdmmCheck& check) { checks.push_back(check); };
    BoxQpSolver solver(backend, qp.P, qp.C, settings);
    Eigen::MatrixXd x, y;
    return solver.solve(qp.q, lower, upper, x, y);
  };
  std::vector<compute::AdmmCheck> tight, loose;
  const BoxQpInfo tightInfo = solveWithScale(1.0, tight);
  const BoxQpInfo looseInfo = solveWithScale(10.0, loose);
  ASSERT_EQ(tightInfo.status, BoxQpStatus::Solved);
  ASSERT_EQ(looseInfo.status, BoxQpStatus::Solved);
  ASSERT_FALSE(tight.empty());
  ASSERT_FALSE(loose.empty());
  // The same iteration up to the looser stop: the first checks see the same iterate.
  EXPECT_EQ(loose.front().primalResidual, tight.front().primalResidual);
  EXPECT_EQ(loose.front().primalTolerance, tight.front().primalTolerance);
  EXPECT_DOUBLE_EQ(loose.front().dualTolerance, 10.0 * tight.front().dualTolerance);
  EXPECT_LT(looseInfo.iterations, tightInfo.iterations);
  EXPECT_LE(loose.back().primalResidual, loose.back().primalTolerance);
  EXPECT_LE(loose.back().dualResidual, loose.back().dualTolerance);
  EXPECT_GT(loose.back().dualResidual, tight.back().dualTolerance) << "the case must stop on the looser tolerance";
}

TEST(BoxQp, ADualToleranceScaleBelowOneIsAUsageError) {
  const EqualityQp qp = consistentEqualityQp(6, 2, 1, 5);
  compute::CpuBackend backend;
  for (const double scale : {0.5, std::nan(""), std::numeric_limits<double>::infinity()}) {
    BoxQpSettings settings;
    settings.dualToleranceScale = scale;
    try {
      BoxQpSolver solver(backend, qp.P, qp.C, settings);
      ADD_FAILURE() << "expected Error(Usage) for scale " << scale;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Usage);
      EXPECT_NE(std::string(e.what()).find("dualToleranceScale"), std::string::npos) << e.what();
    }
  }
}

TEST(BoxQp, ANegativeOrNonFiniteEqualityPolishStiffRhoIsAUsageError) {
  const EqualityQp qp = consistentEqualityQp(6, 2, 1, 5);
  compute::CpuBackend backend;
  for (const double rho : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    BoxQpSettings settings;
    settings.equalityPolishStiffRho = rho;
    try {
      BoxQpSolver solver(backend, qp.P, qp.C, settings);
      ADD_FAILURE() << "expected Error(Usage) for " << rho;
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Usage);
      EXPECT_NE(std::string(e.what()).find("equalityPolishStiffRho"), std::string::npos) << e.what();
    }
  }
  BoxQpSettings none;
  none.equalityPolishStiffRho = 0.0;
  EXPECT_NO_THROW(BoxQpSolver(backend, qp.P, qp.C, none));
}

TEST(BoxQp, WithoutReturnedDualsYComesBackEmptyAndXUnchanged) {
  const EqualityQp qp = consistentEqualityQp(12, 5, 2, 10);
  compute::RelaxedBounds bounds{qp.d, std::vector<char>(5, 1), 0.05};
  bounds.relaxed[0] = 0;
  compute::CpuBackend backend;
  BoxQpSettings settings;
  BoxQpSolver withDuals(backend, qp.P, qp.C, settings);
  settings.returnDuals = false;
  BoxQpSolver withoutDuals(backend, qp.P, qp.C, settings);
  Eigen::MatrixXd x, y, xAlone, yAlone = Eigen::MatrixXd::Zero(5, 2);
  const BoxQpInfo info = withDuals.solve(qp.q, bounds, x, y);
  const BoxQpInfo alone = withoutDuals.solve(qp.q, bounds, xAlone, yAlone);
  EXPECT_EQ(info.status, BoxQpStatus::Solved);
  EXPECT_TRUE(info.polished);
  EXPECT_EQ(alone.iterations, info.iterations);
  EXPECT_EQ(xAlone, x);
  EXPECT_EQ(y.rows(), 5);
  EXPECT_EQ(yAlone.size(), 0);
}

TEST(BoxQp, AnAttemptWithEpsBelowTheAbsoluteToleranceResolvesItsOwnEps) {
  // Rows within eps = 1e-8 of zero (the global step's compatibility rows late in a loop), far
  // below the ADMM's absolute tolerance 1e-6. The ADMM's own point (no polish) keeps every row
  // within eps and a tenth of it (AdmmSettings::epsilonToleranceFraction); with the fraction
  // off, the absolute tolerance alone let rows miss their bounds by more than eps.
  const EqualityQp qp = consistentEqualityQp(12, 5, 2, 11);
  const double eps = 1e-8;
  const compute::RelaxedBounds bounds{Eigen::MatrixXd::Zero(5, 2), std::vector<char>(5, 1), eps};
  compute::CpuBackend backend;
  BoxQpSettings settings;
  settings.polish = false;
  const auto violationWith = [&](double fraction) {
    settings.epsilonToleranceFraction = fraction;
    BoxQpSolver solver(backend, qp.P, qp.C, settings);
    Eigen::MatrixXd x, y;
    const BoxQpInfo info = solver.solve(qp.q, bounds, x, y);
    EXPECT_EQ(info.status, BoxQpStatus::Solved) << "fraction " << fraction;
    return info.maxBoundViolation;
  };
  EXPECT_LE(violationWith(0.1), 0.1 * eps * (1.0 + 1e-6));
  EXPECT_GT(violationWith(0.0), eps);
}

}  // namespace
}  // namespace plano::projective
