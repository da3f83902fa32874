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

BlockMultigrid::BlockMultigrid(const SparseMatrix& K, const BlockMultigridSettings& settings) {
  const BlockAggregation aggregation(K, settings);
  build(aggregation, aggregation.coarsen(K), settings.smootherDamping);
}

BlockMultigrid::BlockMultigrid(const BlockAggregation& aggregation, std::vector<SparseMatrix> levels,
                               double smootherDamping) {
  build(aggregation, std::move(levels), smootherDamping);
}

void BlockMultigrid::build(const BlockAggregation& aggregation, std::vector<SparseMatrix> levels,
                           double smootherDamping) {
  block_ = aggregation.block();
  const int b = block_;
  if (static_cast<int>(levels.size()) != aggregation.levelCount()) {
    throwUsage("multigrid: " + std::to_string(levels.size()) + " level matrices for " +
               std::to_string(aggregation.levelCount()) + " levels");
  }
  for (int l = 0; l < aggregation.levelCount(); ++l) {
    if (levels[l].rows() != aggregation.blocks(l) * b) throwUsage("multigrid: a level matrix of the wrong size");
    Level level{std::move(levels[l]), {}, {}};
    if (l + 1 < aggregation.levelCount()) {
      level.aggregate = aggregation.aggregates(l);
      level.inverseBlocks.resize(aggregation.blocks(l));
      for (Index i = 0; i < aggregation.blocks(l); ++i) {
        const Eigen::MatrixXd D = diagonalBlock(level.K, i, b);
        const Eigen::LLT<Eigen::MatrixXd> llt(D);
        if (llt.info() != Eigen::Success || !D.allFinite()) {
          throwNumerical("multigrid: diagonal block " + std::to_string(i) + " of level " + std::to_string(l) +
                         " is not positive definite");
        }
        level.inverseBlocks[i] = smootherDamping * llt.solve(Eigen::MatrixXd::Identity(b, b));
      }
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
  const int b = block_;
  Eigen::VectorXd z = smooth(level, r);
  Eigen::VectorXd residual = r - level.K * z;
  const Eigen::VectorXd correction = cycle(l + 1, restrictToCoarse(level, rows(l + 1), residual));
  for (std::size_t i = 0; i < level.aggregate.size(); ++i) {
    z.segment(static_cast<Eigen::Index>(i) * b, b) += correction.segment(level.aggregate[i] * b, b);
  }
  residual = r - level.K * z;
  z += smooth(level, residual);
  return z;
}

}  // namespace plano::compute
