#include "subspace/SubspaceBasis.h"

#include "compute/cpu/CpuBackend.h"

namespace plano::subspace {

SubspaceBasis::SubspaceBasis(Eigen::MatrixXd columns, bool separable)
    : columns_(std::move(columns)), separable_(separable) {}

Index SubspaceBasis::dimension() const { return static_cast<Index>(columns_.cols()) * (separable_ ? 3 : 1); }

Index SubspaceBasis::vertexCount() const { return static_cast<Index>(columns_.rows() / (separable_ ? 1 : 3)); }

Positions SubspaceBasis::shape(const Eigen::VectorXd& w) const {
  Positions X(vertexCount(), 3);
  if (separable_) {
    const Eigen::Index d1 = columns_.cols();
    for (int c = 0; c < 3; ++c) {
      const Eigen::Map<const Eigen::VectorXd, 0, Eigen::InnerStride<3>> wc(w.data() + c, d1);
      X.col(c) = columns_ * wc;
    }
  } else {
    Eigen::Map<Eigen::VectorXd>(X.data(), X.size()) = columns_ * w;
  }
  return X;
}

Eigen::VectorXd SubspaceBasis::coefficients(const Positions& X) const {
  if (separable_) {
    // W1 = N1^T X (d1 x 3), flattened row-major: coefficient 3 a + c.
    const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> W1 = columns_.transpose() * X;
    return Eigen::Map<const Eigen::VectorXd>(W1.data(), W1.size());
  }
  return columns_.transpose() * Eigen::Map<const Eigen::VectorXd>(X.data(), X.size());
}

Eigen::MatrixXd SubspaceBasis::compactReducedOperator(compute::Backend& backend, const compute::SparseMatrix& S) const {
  return backend.reducedOperator(S, columns_, separable_ ? 1 : 3);
}

Eigen::MatrixXd SubspaceBasis::reducedOperator(compute::Backend& backend, const compute::SparseMatrix& S) const {
  const Eigen::MatrixXd compact = compactReducedOperator(backend, S);
  if (!separable_) return compact;
  // N = N1 (x) I_3 with coefficient 3 a + c: R = R1 (x) I_3.
  const Eigen::Index d1 = compact.rows();
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(3 * d1, 3 * d1);
  for (Eigen::Index a = 0; a < d1; ++a)
    for (Eigen::Index b = 0; b < d1; ++b)
      for (int c = 0; c < 3; ++c) R(3 * a + c, 3 * b + c) = compact(a, b);
  return R;
}

Eigen::MatrixXd SubspaceBasis::reducedOperator(const compute::SparseMatrix& S) const {
  compute::CpuBackend cpu;
  return reducedOperator(cpu, S);
}

Eigen::MatrixXd SubspaceBasis::coordinateRows(std::span<const Index> coordinates) const {
  const Eigen::Index n = static_cast<Eigen::Index>(coordinates.size());
  Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(n, dimension());
  for (Eigen::Index i = 0; i < n; ++i) {
    const Index q = coordinates[i];
    if (separable_) {
      const Index v = q / 3, c = q % 3;
      for (Eigen::Index a = 0; a < columns_.cols(); ++a) rows(i, 3 * a + c) = columns_(v, a);
    } else {
      rows.row(i) = columns_.row(q);
    }
  }
  return rows;
}

Eigen::MatrixXd SubspaceBasis::storedRows(std::span<const Index> vertices) const {
  const Index perVertex = separable_ ? 1 : 3;
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(vertices.size()) * perVertex, columns_.cols());
  for (std::size_t i = 0; i < vertices.size(); ++i)
    rows.middleRows(static_cast<Eigen::Index>(i) * perVertex, perVertex) =
        columns_.middleRows(vertices[i] * perVertex, perVertex);
  return rows;
}

Eigen::MatrixXd SubspaceBasis::timesVertexRows(const Eigen::MatrixXd& M, const Eigen::MatrixXd& rows) const {
  if (!separable_) return M * rows;
  // Row 3 v + c of N is N1's row v on columns 3 a + c: per axis c, M's columns on that
  // axis (every third) times N1's rows.
  const Eigen::Index r = M.rows(), k = rows.rows(), d1 = rows.cols();
  Eigen::MatrixXd out(r, 3 * d1);
  for (int c = 0; c < 3; ++c) {
    const Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>> onAxis(M.data() + c * r, r, k,
                                                                            Eigen::OuterStride<>(3 * r));
    Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> axisColumns(out.data() + c * r, r, d1,
                                                                     Eigen::OuterStride<>(3 * r));
    axisColumns.noalias() = onAxis * rows;
  }
  return out;
}

double SubspaceBasis::orthogonalityError() const {
  if (columns_.cols() == 0) return 0.0;
  const Eigen::MatrixXd gram = columns_.transpose() * columns_;
  return (gram - Eigen::MatrixXd::Identity(gram.rows(), gram.cols())).cwiseAbs().maxCoeff();
}

}  // namespace plano::subspace
