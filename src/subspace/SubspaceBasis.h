#pragma once
// An orthonormal basis N of a linear space of meshes (the null space of B), stored in the
// compact form the space allows: for a separable space (every face affine) the scalar
// basis N1 (#V x d1) with N = N1 (x) I_3, otherwise N itself (3 #V x d). Every algorithm
// of src/subspace reaches N only through this class, so the separable case costs a third
// of the memory and a ninth of the reduced-operator work.
#include <Eigen/Core>
#include <span>

#include "compute/Backend.h"
#include "mesh/PolygonMesh.h"

namespace plano::subspace {

class SubspaceBasis {
 public:
  SubspaceBasis() = default;
  /// `columns`: N1 (#V x d1) when `separable`, else N (3 #V x d); orthonormal columns.
  SubspaceBasis(Eigen::MatrixXd columns, bool separable);

  /// d = dim of the space (3 d1 when separable).
  Index dimension() const;
  Index vertexCount() const;
  bool separable() const { return separable_; }
  /// The stored columns (N1 or N).
  const Eigen::MatrixXd& columns() const { return columns_; }

  /// The mesh N w (w has d entries). For a separable basis, coefficient 3 a + c moves
  /// coordinate c along scalar column a.
  Positions shape(const Eigen::VectorXd& w) const;
  /// N^T vec(X): the coefficients of the orthogonal projection of X.
  Eigen::VectorXd coefficients(const Positions& X) const;
  /// N N^T vec(X): orthogonal projection of a mesh onto the space.
  Positions project(const Positions& X) const { return shape(coefficients(X)); }

  /// N^T (S (x) I_3) N for a scalar #V x #V operator S (d x d, dense), computed where the
  /// backend runs kernels (Backend::reducedOperator; for a separable basis on N1 only).
  Eigen::MatrixXd reducedOperator(compute::Backend& backend, const compute::SparseMatrix& S) const;
  /// The same on the CPU reference.
  Eigen::MatrixXd reducedOperator(const compute::SparseMatrix& S) const;
  /// N1^T S N1 of a separable basis, N^T (S (x) I_3) N otherwise: the reduced operator in
  /// the compact form (d1 x d1 or d x d).
  Eigen::MatrixXd compactReducedOperator(compute::Backend& backend, const compute::SparseMatrix& S) const;
  /// Rows of N for the full coordinates 3 v + c listed in `coordinates` (#coordinates x d).
  Eigen::MatrixXd coordinateRows(std::span<const Index> coordinates) const;
  /// The stored columns' rows for `vertices`: N1's rows (k x d1) when separable, else N's
  /// rows 3 v, 3 v + 1, 3 v + 2 of each vertex (3k x d).
  Eigen::MatrixXd storedRows(std::span<const Index> vertices) const;
  /// M coordinateRows(3 v_i + c, for each vertex i and axis c in turn), given `rows` =
  /// storedRows(v) (M has 3k columns). For a separable basis per axis, without N's zeros:
  /// a third of the work, and no 3k x d matrix to fill.
  Eigen::MatrixXd timesVertexRows(const Eigen::MatrixXd& M, const Eigen::MatrixXd& rows) const;
  /// max |N^T N - I| entry of the stored columns: how orthonormal the basis is. Costs
  /// #V d^2 (a check for tests and diagnostics, not for every space built).
  double orthogonalityError() const;

 private:
  Eigen::MatrixXd columns_;
  bool separable_ = false;
};

}  // namespace plano::subspace
