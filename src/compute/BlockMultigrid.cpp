#include "compute/BlockMultigrid.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/Error.h"

namespace plano::compute {
namespace {

/// ||K_ij||_F^2 of every coupled block pair (i, j), row by row: couplings[i] lists (j, value).
std::vector<std::vector<std::pair<Index, double>>> blockCouplings(const SparseMatrix& K, int b) {
  const Index blocks = K.rows() / b;
  std::vector<std::vector<std::pair<Index, double>>> couplings(blocks);
  for (Index i = 0; i < blocks; ++i) {
    auto& row = couplings[i];
    for (Index r = i * b; r < (i + 1) * b; ++r) {
      for (SparseMatrix::InnerIterator it(K, r); it; ++it) {
        const Index j = it.col() / b;
        auto found = std::find_if(row.begin(), row.end(), [j](const auto& entry) { return entry.first == j; });
        if (found == row.end()) {
          row.emplace_back(j, 0.0);
          found = row.end() - 1;
        }
        found->second += it.value() * it.value();
      }
    }
  }
  return couplings;
}

Eigen::MatrixXd diagonalBlock(const SparseMatrix& K, Index i, int b) {
  Eigen::MatrixXd block = Eigen::MatrixXd::Zero(b, b);
  for (Index r = i * b; r < (i + 1) * b; ++r) {
    for (SparseMatrix::InnerIterator it(K, r); it; ++it) {
      if (it.col() >= i * b && it.col() < (i + 1) * b) block(r - i * b, it.col() - i * b) = it.value();
    }
  }
  return block;
}

/// The prolongation of an aggregation: row b i + k has a 1 in column b aggregate[i] + k.
SparseMatrix prolongationOf(const std::vector<Index>& aggregate, Index coarseBlocks, int b) {
  SparseMatrix Z(static_cast<Eigen::Index>(aggregate.size()) * b, coarseBlocks * b);
  Z.reserve(Eigen::VectorXi::Constant(Z.rows(), 1));
  for (std::size_t i = 0; i < aggregate.size(); ++i) {
    for (int k = 0; k < b; ++k) Z.insert(static_cast<Index>(i) * b + k, aggregate[i] * b + k) = 1.0;
  }
  Z.makeCompressed();
  return Z;
}

/// Level l's diagonal blocks inverted; throws Error(Numerical) for one that is not positive
/// definite.
std::vector<Eigen::MatrixXd> inverseDiagonalBlocks(const SparseMatrix& K, int b, int level) {
  std::vector<Eigen::MatrixXd> inverses(static_cast<std::size_t>(K.rows() / b));
  for (std::size_t i = 0; i < inverses.size(); ++i) {
    const Eigen::MatrixXd D = diagonalBlock(K, static_cast<Index>(i), b);
    const Eigen::LLT<Eigen::MatrixXd> llt(D);
    if (llt.info() != Eigen::Success || !D.allFinite()) {
      throwNumerical("multigrid: diagonal block " + std::to_string(i) + " of level " + std::to_string(level) +
                     " is not positive definite");
    }
    inverses[i] = llt.solve(Eigen::MatrixXd::Identity(b, b));
  }
  return inverses;
}

/// D^-1 K for K's diagonal blocks' inverses (K's pattern: every diagonal block is stored).
SparseMatrix blockJacobiScaled(const SparseMatrix& K, const std::vector<Eigen::MatrixXd>& inverses, int b) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(inverses.size() * static_cast<std::size_t>(b * b));
  for (std::size_t i = 0; i < inverses.size(); ++i) {
    const auto first = static_cast<Index>(i) * b;
    for (int r = 0; r < b; ++r) {
      for (int c = 0; c < b; ++c) entries.emplace_back(first + r, first + c, inverses[i](r, c));
    }
  }
  SparseMatrix Dinverse(K.rows(), K.cols());
  Dinverse.setFromTriplets(entries.begin(), entries.end());
  return SparseMatrix(Dinverse * K);
}

/// lambda_max(D^-1 K), which is real and positive (D^-1 K is similar to D^-1/2 K D^-1/2), by
/// power iteration from a fixed start: an estimate from below, enough for omega.
double largestEigenvalue(const SparseMatrix& DinverseK) {
  Eigen::VectorXd v(DinverseK.rows());
  for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = 1.0 + static_cast<double>(i % 7) / 7.0;
  v.normalize();
  double lambda = 0.0;
  for (int iteration = 0; iteration < 30; ++iteration) {
    Eigen::VectorXd w = DinverseK * v;
    lambda = w.norm();
    if (!(lambda > 0.0) || !std::isfinite(lambda)) throwNumerical("multigrid: D^-1 K has no positive spectrum");
    v = w / lambda;
  }
  return lambda;
}

}  // namespace

std::vector<Index> pairBlocks(const SparseMatrix& K, int block, Index& pairCount) {
  const Index blocks = K.rows() / block;
  const auto couplings = blockCouplings(K, block);
  std::vector<double> diagonal(blocks, 0.0);
  for (Index i = 0; i < blocks; ++i) {
    for (const auto& [j, value] : couplings[i]) {
      if (j == i) diagonal[i] = std::sqrt(value);
    }
  }
  std::vector<Index> pair(blocks, -1);
  pairCount = 0;
  for (Index i = 0; i < blocks; ++i) {
    if (pair[i] >= 0) continue;
    Index best = -1;
    double strongest = 0.0;
    for (const auto& [j, value] : couplings[i]) {
      if (j == i || pair[j] >= 0) continue;
      const double strength = std::sqrt(value) / std::sqrt(diagonal[i] * diagonal[j]);
      if (strength > strongest) {
        strongest = strength;
        best = j;
      }
    }
    pair[i] = pairCount;
    if (best >= 0) pair[best] = pairCount;
    ++pairCount;
  }
  return pair;
}

BlockAggregation::BlockAggregation(const SparseMatrix& K, const BlockMultigridSettings& settings)
    : block_(settings.block) {
  const int b = block_;
  if (b < 1 || b > 4 || K.rows() != K.cols() || K.rows() % b != 0 || K.rows() == 0) {
    throwUsage("multigrid: a " + std::to_string(K.rows()) + "x" + std::to_string(K.cols()) +
               " matrix in blocks of " + std::to_string(b) + " rows (need a square matrix, 1 to 4 rows per block dividing it)");
  }
  SparseMatrix level = K;
  blocks_.push_back(K.rows() / b);
  while (levelCount() < settings.maxLevels && blocks_.back() > settings.coarsestBlocks) {
    // Pairs of pairs: aggregates of up to four blocks, the coarsening of a 2x2 face patch.
    Index pairs = 0;
    const std::vector<Index> first = pairBlocks(level, b, pairs);
    const SparseMatrix Z1 = prolongationOf(first, pairs, b);
    const SparseMatrix halfway = Z1.transpose() * level * Z1;
    Index coarseBlocks = 0;
    const std::vector<Index> second = pairBlocks(halfway, b, coarseBlocks);
    if (coarseBlocks * 3 > blocks_.back() * 2) break;  // coarsening stalled (< 1.5x): stop here
    std::vector<Index> aggregate(first.size());
    for (std::size_t i = 0; i < first.size(); ++i) aggregate[i] = second[first[i]];
    const SparseMatrix Z = prolongationOf(aggregate, coarseBlocks, b);
    level = Z.transpose() * level * Z;
    aggregates_.push_back(std::move(aggregate));
    blocks_.push_back(coarseBlocks);
  }
}

SparseMatrix BlockAggregation::prolongation(int level) const {
  return prolongationOf(aggregates_[level], blocks_[level + 1], block_);
}

std::vector<SparseMatrix> BlockAggregation::coarsen(const SparseMatrix& A) const {
  if (A.rows() != blocks_.front() * block_ || A.cols() != A.rows()) {
    throwUsage("multigrid: a " + std::to_string(A.rows()) + "x" + std::to_string(A.cols()) + " matrix for " +
               std::to_string(blocks_.front() * block_) + " rows");
  }
  std::vector<SparseMatrix> levels{A};
  levels.front().makeCompressed();
  for (int l = 0; l + 1 < levelCount(); ++l) {
    const SparseMatrix Z = prolongation(l);
    SparseMatrix coarse = Z.transpose() * levels.back() * Z;
    coarse.makeCompressed();
    levels.push_back(std::move(coarse));
  }
  return levels;
}

BlockMultigrid::BlockMultigrid(const SparseMatrix& K, const BlockMultigridSettings& settings)
    : BlockMultigrid(BlockAggregation(K, settings), K, settings) {}

BlockMultigrid::BlockMultigrid(const BlockAggregation& aggregation, const SparseMatrix& K,
                               const BlockMultigridSettings& settings) {
  if (settings.smoothProlongation) {
    buildSmoothed(aggregation, K, settings);
  } else {
    build(aggregation, aggregation.coarsen(K), settings.smootherDamping);
  }
}

void BlockMultigrid::buildSmoothed(const BlockAggregation& aggregation, const SparseMatrix& K,
                                   const BlockMultigridSettings& settings) {
  const int b = aggregation.block();
  std::vector<SparseMatrix> levels{K};
  levels.front().makeCompressed();
  std::vector<SparseMatrix> prolongations;
  std::vector<std::vector<Eigen::MatrixXd>> inverses;
  std::vector<double> dampings;
  for (int l = 0; l + 1 < aggregation.levelCount(); ++l) {
    const SparseMatrix& A = levels.back();
    inverses.push_back(inverseDiagonalBlocks(A, b, l));
    const SparseMatrix DinverseA = blockJacobiScaled(A, inverses.back(), b);
    const double lambda = largestEigenvalue(DinverseA);
    const double omega = 4.0 / (3.0 * lambda);
    dampings.push_back(std::min(settings.smootherDamping, settings.smootherSpectralBound / lambda));
    const SparseMatrix Z = aggregation.prolongation(l);
    SparseMatrix P = Z - SparseMatrix(DinverseA * Z) * omega;
    P.prune(0.0);
    SparseMatrix coarse = SparseMatrix(P.transpose()) * SparseMatrix(A * P);
    coarse.makeCompressed();
    prolongations.push_back(std::move(P));
    levels.push_back(std::move(coarse));
  }
  build(aggregation, std::move(levels), settings.smootherDamping, std::move(inverses), std::move(dampings));
  for (std::size_t l = 0; l < prolongations.size(); ++l) levels_[l].prolongation = std::move(prolongations[l]);
}

BlockMultigrid::BlockMultigrid(const BlockAggregation& aggregation, std::vector<SparseMatrix> levels,
                               double smootherDamping) {
  build(aggregation, std::move(levels), smootherDamping);
}

void BlockMultigrid::build(const BlockAggregation& aggregation, std::vector<SparseMatrix> levels,
                           double smootherDamping, std::vector<std::vector<Eigen::MatrixXd>> inverses,
                           std::vector<double> dampings) {
  block_ = aggregation.block();
  const int b = block_;
  if (static_cast<int>(levels.size()) != aggregation.levelCount()) {
    throwUsage("multigrid: " + std::to_string(levels.size()) + " level matrices for " +
               std::to_string(aggregation.levelCount()) + " levels");
  }
  for (int l = 0; l < aggregation.levelCount(); ++l) {
    if (levels[l].rows() != aggregation.blocks(l) * b) throwUsage("multigrid: a level matrix of the wrong size");
    Level level{std::move(levels[l]), {}, {}, {}};
    if (l + 1 < aggregation.levelCount()) {
      level.aggregate = aggregation.aggregates(l);
      level.inverseBlocks = static_cast<std::size_t>(l) < inverses.size() ? std::move(inverses[l])
                                                                            : inverseDiagonalBlocks(level.K, b, l);
      const double damping = static_cast<std::size_t>(l) < dampings.size() ? dampings[l] : smootherDamping;
      for (Eigen::MatrixXd& inverse : level.inverseBlocks) inverse *= damping;
    }
    levels_.push_back(std::move(level));
  }
  coarsest_.compute(Eigen::SparseMatrix<double>(levels_.back().K));
  if (coarsest_.info() != Eigen::Success) throwNumerical("multigrid: the coarsest matrix is not positive definite");
}

Eigen::VectorXd BlockMultigrid::apply(const Eigen::VectorXd& r) const {
  if (r.size() != levels_.front().K.rows()) {
    throwUsage("multigrid: a vector of " + std::to_string(r.size()) + " entries for " +
               std::to_string(levels_.front().K.rows()) + " rows");
  }
  return cycle(0, r);
}

Eigen::VectorXd BlockMultigrid::smooth(const Level& level, const Eigen::VectorXd& r) const {
  const int b = block_;
  Eigen::VectorXd z(r.size());
  for (std::size_t i = 0; i < level.inverseBlocks.size(); ++i) {
    const auto first = static_cast<Eigen::Index>(i) * b;
    z.segment(first, b) = level.inverseBlocks[i] * r.segment(first, b);
  }
  return z;
}

Eigen::VectorXd BlockMultigrid::restrictToCoarse(const Level& level, Index coarseRows, const Eigen::VectorXd& r) const {
  if (level.prolongation.size() > 0) return level.prolongation.transpose() * r;
  const int b = block_;
  Eigen::VectorXd coarse = Eigen::VectorXd::Zero(coarseRows);
  for (std::size_t i = 0; i < level.aggregate.size(); ++i) {
    coarse.segment(level.aggregate[i] * b, b) += r.segment(static_cast<Eigen::Index>(i) * b, b);
  }
  return coarse;
}

Eigen::VectorXd BlockMultigrid::cycle(int l, const Eigen::VectorXd& r) const {
  if (l + 1 == levelCount()) return coarsest_.solve(r);
  const Level& level = levels_[l];
  Eigen::VectorXd z = smooth(level, r);
  Eigen::VectorXd residual = r - level.K * z;
  addProlongated(level, cycle(l + 1, restrictToCoarse(level, rows(l + 1), residual)), z);
  residual = r - level.K * z;
  z += smooth(level, residual);
  return z;
}

void BlockMultigrid::addProlongated(const Level& level, const Eigen::VectorXd& coarse, Eigen::VectorXd& z) const {
  if (level.prolongation.size() > 0) {
    z += level.prolongation * coarse;
    return;
  }
  const int b = block_;
  for (std::size_t i = 0; i < level.aggregate.size(); ++i) {
    z.segment(static_cast<Eigen::Index>(i) * b, b) += coarse.segment(level.aggregate[i] * b, b);
  }
}

}  // namespace plano::compute
