#include "subspace/Eigenshapes.h"

#include <Eigen/Eigenvalues>
#include <Spectra/MatOp/DenseSymMatProd.h>
#include <Spectra/SymEigsSolver.h>
#include <string>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"

namespace plano::subspace {
namespace {

struct Eigenpairs {
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;
};

/// The `count` smallest eigenpairs of the symmetric matrix R, ascending.
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
  Spectra::DenseSymMatProd<double> op(R);
  const Index ncv = std::min<Index>(n, std::max<Index>(2 * count + 1, count + 20));
  Spectra::SymEigsSolver<Spectra::DenseSymMatProd<double>> eigs(op, count, ncv);
  eigs.init();
  eigs.compute(Spectra::SortRule::SmallestAlge, settings.maxIterations, settings.tolerance,
               Spectra::SortRule::SmallestAlge);
  info.dense = false;
  info.iterations = static_cast<Index>(eigs.num_iterations());
  if (eigs.info() != Spectra::CompInfo::Successful) {
    info.status = EigenshapeStatus::NotConverged;
    throwNumerical("eigenshapes: Spectra did not converge in " + std::to_string(settings.maxIterations) +
                   " iterations");
  }
  return {eigs.eigenvalues(), eigs.eigenvectors()};
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
