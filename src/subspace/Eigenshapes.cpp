#include "subspace/Eigenshapes.h"

#include <Eigen/Eigenvalues>
#include <Spectra/SymEigsShiftSolver.h>
#include <algorithm>
#include <numeric>
#include <string>
#include <vector>

#include "compute/cpu/CpuBackend.h"
#include "core/Cancellation.h"
#include "core/Error.h"

namespace plano::subspace {
namespace {

struct Eigenpairs {
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
};

/// (R - sigma I)^-1 x through a Cholesky factor: Spectra's shift-invert operator for a
/// sigma below R's spectrum (R is positive semidefinite: R - sigma I is definite).
class ShiftedCholeskySolve {
 public:
  using Scalar = double;
  explicit ShiftedCholeskySolve(const Eigen::MatrixXd& R) : R_(R) {}
  Eigen::Index rows() const { return R_.rows(); }
  Eigen::Index cols() const { return R_.cols(); }
  void set_shift(double sigma) {
    Eigen::MatrixXd shifted = R_;
    shifted.diagonal().array() -= sigma;
    factor_.compute(shifted);
  }
  bool factored() const { return factor_.info() == Eigen::Success; }
  void perform_op(const double* x, double* y) const {
    Eigen::Map<Eigen::VectorXd>(y, rows()) = factor_.solve(Eigen::Map<const Eigen::VectorXd>(x, rows()));
  }

 private:
  const Eigen::MatrixXd& R_;
  Eigen::LLT<Eigen::MatrixXd> factor_;
};

/// The eigenvalues of R's approximate eigenvectors (columns of V) as their Rayleigh
/// quotients v^T R v / v^T v, the pairs sorted ascending. Shift-invert Ritz values come from
/// solves with R - sigma I, whose rounding the tiny shift amplifies by 1 / sigma along R's
/// null space: on a 14 x 14 grid's affine space they were off by 7.6e-9 relative on one
/// machine and within 1e-9 on another. A Rayleigh quotient's error is quadratic in the
/// vector's (1e-16 there).
Eigenpairs withRayleighQuotients(const Eigen::MatrixXd& R, const Eigen::MatrixXd& V) {
  const Eigen::Index count = V.cols();
  Eigen::VectorXd quotients(count);
  for (Eigen::Index k = 0; k < count; ++k) {
    quotients[k] = V.col(k).dot(R * V.col(k)) / V.col(k).squaredNorm();
  }
  std::vector<Eigen::Index> order(static_cast<std::size_t>(count));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return quotients[a] < quotients[b]; });
  Eigenpairs pairs{Eigen::VectorXd(count), Eigen::MatrixXd(V.rows(), count)};
  for (Eigen::Index k = 0; k < count; ++k) {
    pairs.values[k] = quotients[order[k]];
    pairs.vectors.col(k) = V.col(order[k]);
  }
  return pairs;
}

/// The `count` smallest eigenpairs of the symmetric positive semidefinite matrix R, ascending.
Eigenpairs smallestEigenpairs(const Eigen::MatrixXd& R, Index count, const EigenshapeSettings& settings,
                              EigenshapeInfo& info) {
  const Index n = static_cast<Index>(R.rows());
  count = std::min(count, n);
  info.reducedSize = n;
  if (n <= settings.denseLimit || count + 2 >= n) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(R);
    if (eig.info() != Eigen::Success) throwNumerical("eigenshapes: dense eigensolver failed");
    info.dense = true;
    return {eig.eigenvalues().head(count), eig.eigenvectors().leftCols(count)};
  }
  // Shift-invert Lanczos around a sigma just below 0: the smallest eigenvalues of a reduced
  // Laplacian cluster near 0, where plain Lanczos on R needs thousands of products (a
  // 7 610-dimensional space: ~75 s); on (R - sigma I)^-1 they are the largest and well apart,
  // and a few dozen solves with one Cholesky factor find them. The shift grows when rounding
  // leaves R - sigma I indefinite.
  const double scale = std::max(R.cwiseAbs().maxCoeff(), 1e-300);
  const Index ncv = std::min<Index>(n, std::max<Index>(2 * count + 1, count + 20));
  ShiftedCholeskySolve op(R);
  for (double shift = 1e-10 * scale; shift <= 1e-4 * scale; shift *= 100.0) {
    throwIfCancelled("the eigenshapes");
    Spectra::SymEigsShiftSolver<ShiftedCholeskySolve> eigs(op, count, ncv, -shift);
    if (!op.factored()) continue;
    eigs.init();
    eigs.compute(Spectra::SortRule::LargestMagn, settings.maxIterations, settings.tolerance,
                 Spectra::SortRule::SmallestAlge);
    info.dense = false;
    info.iterations = static_cast<Index>(eigs.num_iterations());
    if (eigs.info() != Spectra::CompInfo::Successful) {
      info.status = EigenshapeStatus::NotConverged;
      throwNumerical("eigenshapes: Spectra did not converge in " + std::to_string(settings.maxIterations) +
                     " iterations");
    }
    return withRayleighQuotients(R, eigs.eigenvectors());
  }
  throwNumerical("eigenshapes: the reduced operator is not positive semidefinite (no Cholesky factor below its spectrum)");
}

}  // namespace

Eigenshapes computeEigenshapes(compute::Backend& backend, const SubspaceBasis& N, const compute::SparseMatrix& L,
                               const EigenshapeSettings& settings, EigenshapeInfo* info) {
  EigenshapeInfo local;
  Eigenshapes shapes;
  const Index d = N.dimension();
  const Index count = std::min(settings.count, d);
  if (count <= 0) {
    shapes.coefficients.resize(d, 0);
    if (info) *info = local;
    return shapes;
  }
  // For a separable basis N^T (L (x) I3) N = (N1^T L N1) (x) I3: the compact operator is
  // the scalar problem, whose eigenpairs repeat per coordinate.
  const Eigen::MatrixXd R = N.compactReducedOperator(backend, L);
  if (N.separable()) {
    const Eigenpairs pairs = smallestEigenpairs(0.5 * (R + R.transpose()), (count + 2) / 3, settings, local);
    shapes.coefficients = Eigen::MatrixXd::Zero(d, count);
    shapes.frequencies.resize(count);
    for (Index k = 0; k < count; ++k) {
      const Index j = k / 3, c = k % 3;
      shapes.frequencies[k] = pairs.values[j];
      for (Eigen::Index a = 0; a < pairs.vectors.rows(); ++a) shapes.coefficients(3 * a + c, k) = pairs.vectors(a, j);
    }
  } else {
    const Eigenpairs pairs = smallestEigenpairs(0.5 * (R + R.transpose()), count, settings, local);
    shapes.coefficients = pairs.vectors;
    shapes.frequencies = pairs.values;
  }
  if (info) *info = local;
  return shapes;
}

Eigenshapes computeEigenshapes(const SubspaceBasis& N, const compute::SparseMatrix& L,
                               const EigenshapeSettings& settings, EigenshapeInfo* info) {
  compute::CpuBackend cpu;
  return computeEigenshapes(cpu, N, L, settings, info);
}

Positions bandPass(const SubspaceBasis& N, const Eigenshapes& shapes, const Positions& base, Index lo, Index hi,
                   double amplitude) {
  if (lo < 0 || hi > shapes.count() || lo >= hi) {
    throwUsage("band " + std::to_string(lo) + ":" + std::to_string(hi) + " is empty or outside the " +
               std::to_string(shapes.count()) + " computed eigenshapes");
  }
  const double diagonal = boundingBoxDiagonal(base);
  Positions out = base;
  for (Index k = lo; k < hi; ++k) {
    const Positions X = N.shape(shapes.coefficients.col(k));
    const double peak = X.rowwise().norm().maxCoeff();
    if (peak > 0.0) out += (amplitude * diagonal / peak) * X;
  }
  return out;
}

}  // namespace plano::subspace
