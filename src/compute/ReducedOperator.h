#pragma once
// The reduced operator of a linear space of meshes (linear-spaces paper, §3-4): for an
// orthonormal basis N of the space and a scalar per-vertex operator S (a Laplacian, the
// centred-corner matrix of the ASAP/ARAP energy, L^T L of the fundamental shapes),
//
//   R = N^T (S (x) I_k) N,
//
// N with k #V rows, row k v + c the coordinate c of vertex v (k = 1 for a separable
// space's scalar basis N1, k = 3 otherwise), S #V x #V. It is the d x d matrix behind the
// eigenshapes, the subspace deformation's global matrix and the fundamental shapes, and
// its cost, 2 k #V d^2 multiply-adds, dominates them once d reaches the hundreds.
// Backend::reducedOperator runs it where the backend runs kernels; this is the CPU
// reference.
#include <Eigen/Core>

#include "compute/Backend.h"

namespace plano::compute {

/// Error(Usage) unless S is square, coordinates >= 1 and N has coordinates * S.rows() rows.
void checkReducedOperatorInputs(const SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates);

/// R = N^T (S (x) I_k) N on the CPU (k = coordinates): (S (x) I_k) N with Eigen column by
/// column, each column viewed as a row-major #V x k matrix, then one dense product, of its
/// lower half only when S is symmetric (cpu/SymmetricProduct.h). Throws Interrupted on a
/// cancellation request.
Eigen::MatrixXd reducedOperatorReference(const SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates);

}  // namespace plano::compute
