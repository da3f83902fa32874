#include "projective/BoxQp.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/Error.h"

namespace plano::projective {
namespace {

double infNorm(const Eigen::MatrixXd& m) { return m.size() == 0 ? 0.0 : m.cwiseAbs().maxCoeff(); }

compute::SparseMatrix identity(Eigen::Index n, double value) {
  compute::SparseMatrix I(n, n);
  I.setIdentity();
  return I * value;
}

double boundViolation(const Eigen::MatrixXd& Cx, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper) {
  if (Cx.size() == 0) return 0.0;
  return std::max({0.0, (lower - Cx).maxCoeff(), (Cx - upper).maxCoeff()});
}

}  // namespace

const char* toString(BoxQpStatus status) {
  switch (status) {
    case BoxQpStatus::Solved: return "solved";
    case BoxQpStatus::PrimalInfeasible: return "primal_infeasible";
    case BoxQpStatus::MaxIterationsReached: return "max_iterations";
    case BoxQpStatus::NonFinite: return "non_finite";
  }
  return "unknown";
}

BoxQpSolver::BoxQpSolver(compute::Backend& backend, compute::SparseMatrix P, compute::SparseMatrix C,
                         const BoxQpSettings& settings)
    : backend_(backend), settings_(settings), P_(std::move(P)), C_(std::move(C)), rho_(settings.rho) {
  if (P_.rows() != P_.cols() || C_.cols() != P_.rows()) {
    throwUsage("box QP: P is " + std::to_string(P_.rows()) + "x" + std::to_string(P_.cols()) + " and C is " +
               std::to_string(C_.rows()) + "x" + std::to_string(C_.cols()) + " (need n x n and m x n)");
  }
  Ct_ = C_.transpose();
}

void BoxQpSolver::factor(const Eigen::VectorXd& rhoPerRow) {
  const compute::SparseMatrix K =
      P_ + identity(P_.rows(), settings_.sigma) + compute::SparseMatrix(Ct_ * rhoPerRow.asDiagonal() * C_);
  solver_ = backend_.createSpdSolver(K, settings_.linearSolver);
  factoredRho_ = rhoPerRow;
}

BoxQpInfo BoxQpSolver::solve(const Eigen::MatrixXd& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                             Eigen::MatrixXd& x, Eigen::MatrixXd& y) {
  const Eigen::Index n = P_.rows();
  const Eigen::Index m = C_.rows();
  const Eigen::Index k = q.cols();
  if (q.rows() != n || lower.rows() != m || upper.rows() != m || lower.cols() != k || upper.cols() != k) {
    throwUsage("box QP: q, lower and upper must be n x k, m x k, m x k");
  }
  if ((lower.array() > upper.array()).any()) throwUsage("box QP: a lower bound exceeds its upper bound");
  if (x.size() == 0) x = Eigen::MatrixXd::Zero(n, k);
  if (y.size() == 0) y = Eigen::MatrixXd::Zero(m, k);
  if (x.rows() != n || x.cols() != k || y.rows() != m || y.cols() != k) {
    throwUsage("box QP: warm starts x and y must be n x k and m x k");
  }

  std::vector<char> equality(m);
  for (Eigen::Index i = 0; i < m; ++i) equality[i] = (lower.row(i).array() == upper.row(i).array()).all();
  auto rhoVector = [&] {
    Eigen::VectorXd r(m);
    for (Eigen::Index i = 0; i < m; ++i) r[i] = equality[i] ? rho_ * settings_.equalityRhoScale : rho_;
    return r;
  };
  BoxQpInfo info;
  Eigen::VectorXd rho = rhoVector();
  if (!solver_ || factoredRho_.size() != m || factoredRho_ != rho) {
    factor(rho);
    ++info.factorizations;
  }

  const double alpha = settings_.relaxation;
  Eigen::MatrixXd z = (C_ * x).cwiseMax(lower).cwiseMin(upper);
  Eigen::MatrixXd xTilde = x;
  Eigen::MatrixXd yPrevious = y;
  const double qNorm = infNorm(q);

  // Residuals, tolerances and the rho balance at the current iterate. Returns true when converged.
  double rhoBalance = 1.0;
  auto converged = [&]() {
    const Eigen::MatrixXd Cx = C_ * x;
    const Eigen::MatrixXd Px = P_ * x;
    const Eigen::MatrixXd Cty = Ct_ * y;
    info.primalResidual = infNorm(Cx - z);
    info.dualResidual = infNorm(Px + q + Cty);
    const double primalScale = std::max(infNorm(Cx), infNorm(z));
    const double dualScale = std::max({infNorm(Px), infNorm(Cty), qNorm});
    const double epsPrimal = settings_.absoluteTolerance + settings_.relativeTolerance * primalScale;
    const double epsDual = settings_.absoluteTolerance + settings_.relativeTolerance * dualScale;
    const double tiny = 1e-30;
    rhoBalance = std::sqrt((info.primalResidual / std::max(primalScale, tiny)) /
                           std::max(info.dualResidual / std::max(dualScale, tiny), tiny));
    return info.primalResidual <= epsPrimal && info.dualResidual <= epsDual;
  };

  // OSQP's primal infeasibility certificate from the last dual step dy: C^T dy ~ 0 and
  // u^T max(dy, 0) + l^T min(dy, 0) < 0 (for the dy normalized to unit inf-norm).
  auto infeasible = [&]() {
    const Eigen::MatrixXd dy = y - yPrevious;
    for (Eigen::Index c = 0; c < k; ++c) {
      const double norm = dy.col(c).cwiseAbs().maxCoeff();
      if (!(norm > 0.0)) continue;
      const Eigen::VectorXd d = dy.col(c) / norm;
      const double support = upper.col(c).dot(d.cwiseMax(0.0)) + lower.col(c).dot(d.cwiseMin(0.0));
      if (infNorm(Ct_ * d) <= settings_.infeasibilityTolerance && support <= -settings_.infeasibilityTolerance) {
        return true;
      }
    }
    return false;
  };

  if (converged()) {
    info.status = BoxQpStatus::Solved;
  } else {
    for (int iteration = 1; iteration <= settings_.maxIterations; ++iteration) {
      const bool check = iteration % settings_.checkInterval == 0 || iteration == settings_.maxIterations;
      const Eigen::MatrixXd rhs = settings_.sigma * x - q + Ct_ * (rho.asDiagonal() * z - y);
      solver_->solve(rhs, xTilde);
      const Eigen::MatrixXd zTilde = C_ * xTilde;
      x = alpha * xTilde + (1.0 - alpha) * x;
      const Eigen::MatrixXd zRelaxed = alpha * zTilde + (1.0 - alpha) * z;
      const Eigen::MatrixXd zNext =
          (zRelaxed + rho.cwiseInverse().asDiagonal() * y).cwiseMax(lower).cwiseMin(upper);
      if (check) yPrevious = y;
      y += rho.asDiagonal() * (zRelaxed - zNext);
      z = zNext;
      info.iterations = iteration;
      if (!check) continue;
      if (!x.allFinite() || !y.allFinite()) {
        info.status = BoxQpStatus::NonFinite;
        break;
      }
      if (converged()) {
        info.status = BoxQpStatus::Solved;
        break;
      }
      if (infeasible()) {
        info.status = BoxQpStatus::PrimalInfeasible;
        break;
      }
      if (settings_.adaptiveRho) {
        const double proposed = std::clamp(rho_ * rhoBalance, 1e-6, 1e6);
        if (proposed > rho_ * settings_.adaptiveRhoFactor || proposed < rho_ / settings_.adaptiveRhoFactor) {
          rho_ = proposed;
          rho = rhoVector();
          factor(rho);
          ++info.factorizations;
        }
      }
    }
  }

  if (info.status == BoxQpStatus::Solved && settings_.polish && info.iterations > 0) {
    info.polished = polish(q, lower, upper, z, x, y);
  }
  const Eigen::MatrixXd Cx = C_ * x;
  info.maxBoundViolation = boundViolation(Cx, lower, upper);
  if (info.polished) info.primalResidual = info.maxBoundViolation;
  info.rho = rho_;
  return info;
}

bool BoxQpSolver::polish(const Eigen::MatrixXd& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                         const Eigen::MatrixXd& z, Eigen::MatrixXd& x, Eigen::MatrixXd& y) {
  const Eigen::Index n = P_.rows();
  const Eigen::Index m = C_.rows();
  const double before = boundViolation(C_ * x, lower, upper);
  Eigen::MatrixXd xPolished = x;
  Eigen::MatrixXd yPolished = Eigen::MatrixXd::Zero(m, q.cols());
  const double rhoP = settings_.polishRho;
  // Columns with the same active set (always the case for all-equality problems) share
  // one factorization.
  std::vector<Eigen::Index> factoredRows;
  std::unique_ptr<compute::SpdSolver> solver;
  for (Eigen::Index c = 0; c < q.cols(); ++c) {
    // Active set as in OSQP: equality rows, and rows whose dual pushes z onto a bound.
    std::vector<Eigen::Index> rows;
    std::vector<double> targets;
    for (Eigen::Index i = 0; i < m; ++i) {
      const double l = lower(i, c), u = upper(i, c);
      if (l == u || z(i, c) - l < -y(i, c)) {
        rows.push_back(i);
        targets.push_back(l);
      } else if (u - z(i, c) < y(i, c)) {
        rows.push_back(i);
        targets.push_back(u);
      }
    }
    const auto active = static_cast<Eigen::Index>(rows.size());
    compute::SparseMatrix selector(active, m);
    std::vector<Eigen::Triplet<double>> entries;
    for (Eigen::Index r = 0; r < active; ++r) entries.emplace_back(r, rows[r], 1.0);
    selector.setFromTriplets(entries.begin(), entries.end());
    const compute::SparseMatrix CA = selector * C_;
    const compute::SparseMatrix CAt = CA.transpose();
    const Eigen::VectorXd b = Eigen::Map<const Eigen::VectorXd>(targets.data(), active);
    if (!solver || rows != factoredRows) {
      const compute::SparseMatrix K = P_ + identity(n, settings_.sigma) + compute::SparseMatrix(rhoP * (CAt * CA));
      // The stiff polish system can be too ill-conditioned to factor; polishing is an
      // optional refinement, so the ADMM solution stands.
      try {
        solver = backend_.createSpdSolver(K, settings_.linearSolver);
      } catch (const Error&) {
        return false;
      }
      factoredRows = rows;
    }
    // Method of multipliers on the equality-constrained QP, warm-started from the ADMM duals.
    Eigen::VectorXd lambda = selector * y.col(c);
    Eigen::MatrixXd xc = x.col(c);
    for (int it = 0; it < settings_.polishIterations; ++it) {
      const Eigen::MatrixXd rhs = settings_.sigma * xc - q.col(c) - CAt * lambda + rhoP * (CAt * b);
      solver->solve(rhs, xc);
      const Eigen::VectorXd r = CA * xc - b;
      lambda += rhoP * r;
      if (infNorm(r) <= 1e-15 * std::max(1.0, infNorm(b))) break;
    }
    if (!xc.allFinite()) return false;
    xPolished.col(c) = xc;
    yPolished.col(c) = selector.transpose() * lambda;
  }
  const double after = boundViolation(C_ * xPolished, lower, upper);
  if (!(after <= std::max(before, 1e-12))) return false;
  x = xPolished;
  y = yPolished;
  return true;
}

}  // namespace plano::projective
