#pragma once
// A^T B for two tall matrices whose product is known to be symmetric, as N^T (S N) for a
// symmetric S (the linear spaces' reduced operators, compute/ReducedOperator.h). Only the
// column blocks on and below the diagonal are multiplied, then mirrored: about half the
// multiply-adds of the full product. The blocks go through BLAS (OpenBLAS, installed by
// scripts/setup.sh, picks vectorised kernels for the machine at run time: ~3x Eigen's
// portable ones on a 17 916 x 2 000 product here), and between them a cancellation request
// is noticed, where one product of a ten-thousand-dimensional space is minutes of work.
#include <Eigen/Core>

namespace plano::compute {

/// The lower triangle of A^T B mirrored to the upper one (A and B of the same size).
/// Throws Interrupted between blocks on a cancellation request, Error(Usage) for sizes
/// that differ.
Eigen::MatrixXd symmetricTransposeProduct(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B);

}  // namespace plano::compute
