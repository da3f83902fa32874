#pragma once
// An aggregation multigrid V-cycle for the global step's ADMM matrix
// K = P + sigma I + C^T diag(rho) C, the host reference of a device preconditioner.
//
// Why: with the stiff penalties of the ε-relaxed constraints, K is dominated by C^T rho C,
// whose near-null space (the compatible maps) is global; block-Jacobi over each face's
// four map entries captures only the coupling inside a face, and its PCG iteration count
// grows with rho and with the mesh (README, "The GPU target"). A coarse space of maps that
// are constant over small groups of faces is close to that near-null space: as the PCG
// preconditioner, a V-cycle over such groups needs 9-15x fewer iterations on 1k-4k-face
// global-step matrices, and the cut grows with the mesh (BlockMultigridTest). The device's
// cycle (vk::Multigrid) preconditions the global step's ADMM above 128 faces (below, its
// coarsest level alone: K's dense inverse).
//
// Construction (plain aggregation AMG, block version): the unknowns come in blocks of b
// rows (a face's map entries); each level pairs every block with its most strongly coupled
// unpaired neighbour, twice, so that an aggregate holds up to four blocks; the prolongation
// copies a coarse block into each of its fine blocks (entry k to entry k); coarse matrices
// are Galerkin products. Smoothing is damped block-Jacobi, once before and once after the
// coarse correction, so the cycle is a symmetric operator; the coarsest level is solved
// exactly. Everything is a sum over a fixed pattern or a small dense block, the operations
// a device implementation needs.
#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <vector>

#include "compute/Backend.h"

namespace plano::compute {

struct BlockMultigridSettings {
  int block = 4;              ///< Rows per block (1 to 4), dividing the matrix size.
  Index coarsestBlocks = 64;  ///< Stop coarsening at or below this many blocks.
  int maxLevels = 24;
  /// Damping of the block-Jacobi smoother. Undamped needs the fewest iterations on the
  /// global-step matrices measured (0.7 takes 5-10 % more; BlockMultigridTest).
  double smootherDamping = 1.0;
  /// Smoothed aggregation: each prolongation is the aggregates' copy Z smoothed by one
  /// damped block-Jacobi step, P = (I - omega D^-1 K) Z with omega = 4 / (3 lambda_max(D^-1 K)),
  /// and the coarse matrices are P^T K P. The near-null space of C^T rho C (the compatible
  /// map fields, which vary from face to face) is then interpolated linearly instead of
  /// piecewise constantly, and the PCG iterations stop growing with the mesh. Measured
  /// on the global step's matrices, rho_eq 1e3 (plain -> smoothed): 1k faces 25 -> 13, 4k
  /// 31 -> 10, 16k 45 -> 10, 65k 61 -> 10; rho_eq 1e5: 142 -> 87, 114 -> 50, 94 -> 27, 86 -> 16.
  /// The price is denser coarse levels (65k faces: operator complexity 2.3 against 1.3)
  /// and a costlier setup; on the host the smoothed solve of BM_MultigridPcg is the slower
  /// one (2.1-2.6x the time per iteration for half the iterations), so the host reference
  /// keeps it off by default. The device's cycle forms it at each rho update
  /// (vk::SmoothedTransfer; AdmmSettings::smoothedMultigrid, on in the global step).
  bool smoothProlongation = false;
  /// With smoothProlongation: each level's smoother damping is at most this bound over
  /// lambda_max(D^-1 K) (the estimate that sets omega). The symmetric V-cycle is positive
  /// definite only where the damped smoother converges (damping * lambda_max < 2), and the
  /// smoothed coarse levels have lambda_max above 2 (2.0-2.4 on the global step's matrices
  /// at rho_eq 1e5, 16x16 to 48x48 grids). Undamped, the 16x16 cycle's M K had an eigenvalue
  /// of -0.07 at rho_eq 1e5, and the device's PCG stopped a few iterations in, far from the
  /// solution; with this bound M K's spectrum is [0.0073, 1] there and [0.73, 1] at rho_eq
  /// 1e2 (plain aggregation: [0.0040, 1], [0.36, 1]). The power iteration estimates lambda
  /// from below: 1.5 leaves a quarter's margin to 2 (1.9 gives [0.0085, 1] but none).
  double smootherSpectralBound = 1.5;
};

/// Pair every block with its most strongly coupled unpaired neighbour (coupling:
/// ||K_ij||_F / sqrt(||K_ii||_F ||K_jj||_F) over the b x b blocks), in block order; a block
/// without an unpaired neighbour stays alone. Returns each block's pair index
/// (0 .. pairCount - 1), pairs numbered in order of their first block.
std::vector<Index> pairBlocks(const SparseMatrix& K, int block, Index& pairCount);

/// The levels' aggregates, chosen once from a matrix's couplings (pairs of pairs per level,
/// until at most coarsestBlocks blocks remain or coarsening stalls). Every matrix with the
/// same structure (K = K0 + rho K1 for any rho) can then be coarsened with them.
class BlockAggregation {
 public:
  /// Throws Error(Usage) for a bad block size.
  BlockAggregation(const SparseMatrix& K, const BlockMultigridSettings& settings = {});

  int levelCount() const { return static_cast<int>(blocks_.size()); }
  int block() const { return block_; }
  /// Blocks of level l (level 0: the matrix's).
  Index blocks(int level) const { return blocks_[level]; }
  /// Level l's aggregate of each of its blocks (a block of level l + 1), l < levelCount() - 1.
  const std::vector<Index>& aggregates(int level) const { return aggregates_[level]; }
  /// Prolongation Z_l from level l + 1 to level l: row b i + k has a 1 in column b a_i + k.
  SparseMatrix prolongation(int level) const;
  /// A on every level: A_0 = A, A_{l+1} = Z_l^T A_l Z_l (compressed).
  std::vector<SparseMatrix> coarsen(const SparseMatrix& A) const;

 private:
  int block_;
  std::vector<Index> blocks_;
  std::vector<std::vector<Index>> aggregates_;
};

/// The V-cycle over given level matrices (those of BlockAggregation::coarsen).
class BlockMultigrid {
 public:
  /// Aggregate K and build its levels. Throws Error(Usage) for a bad block size,
  /// Error(Numerical) when a diagonal block or the coarsest matrix is not positive definite.
  /// With settings.smoothProlongation, the smoothed-aggregation cycle over K's aggregation.
  explicit BlockMultigrid(const SparseMatrix& K, const BlockMultigridSettings& settings = {});
  /// The cycle of K over a given aggregation (that of another matrix of K's structure, as
  /// the device's cycle keeps it for every rho); settings.block and the coarsening limits
  /// are the aggregation's.
  BlockMultigrid(const BlockAggregation& aggregation, const SparseMatrix& K, const BlockMultigridSettings& settings);
  /// The cycle of `levels` (one matrix per level of `aggregation`).
  BlockMultigrid(const BlockAggregation& aggregation, std::vector<SparseMatrix> levels,
                 double smootherDamping = BlockMultigridSettings{}.smootherDamping);

  /// One V-cycle from a zero initial guess: z ~ K^-1 r.
  Eigen::VectorXd apply(const Eigen::VectorXd& r) const;

  int levelCount() const { return static_cast<int>(levels_.size()); }
  /// Rows of level l's matrix (level 0 is K).
  Index rows(int level) const { return levels_[level].K.rows(); }
  /// Stored entries of level l's matrix: their sum over the levels, over K's, is the cycle's
  /// operator complexity.
  Index nonZeros(int level) const { return levels_[level].K.nonZeros(); }
  /// Level l's aggregate of each of its blocks (a block of level l + 1).
  const std::vector<Index>& aggregates(int level) const { return levels_[level].aggregate; }

 private:
  struct Level {
    SparseMatrix K;
    std::vector<Eigen::MatrixXd> inverseBlocks;  ///< Damped: omega * K_ii^-1.
    std::vector<Index> aggregate;                ///< Block -> coarse block (empty on the coarsest).
    SparseMatrix prolongation;                   ///< Smoothed P (empty: the aggregates' copy Z).
  };
  void buildSmoothed(const BlockAggregation& aggregation, const SparseMatrix& K, const BlockMultigridSettings& settings);
  /// `inverses`: each level's undamped diagonal-block inverses where the caller has them
  /// (buildSmoothed), else empty and computed here; `dampings` each level's smoother damping
  /// where the caller chose them (else smootherDamping everywhere).
  void build(const BlockAggregation& aggregation, std::vector<SparseMatrix> levels, double smootherDamping,
             std::vector<std::vector<Eigen::MatrixXd>> inverses = {}, std::vector<double> dampings = {});
  Eigen::VectorXd cycle(int level, const Eigen::VectorXd& r) const;
  Eigen::VectorXd smooth(const Level& level, const Eigen::VectorXd& r) const;
  Eigen::VectorXd restrictToCoarse(const Level& level, Index coarseRows, const Eigen::VectorXd& r) const;
  void addProlongated(const Level& level, const Eigen::VectorXd& coarse, Eigen::VectorXd& z) const;

  int block_ = 1;
  std::vector<Level> levels_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> coarsest_;
};

}  // namespace plano::compute
