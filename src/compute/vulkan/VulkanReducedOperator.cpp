#include "compute/vulkan/VulkanReducedOperator.h"

#include <algorithm>
#include <string>
#include <vector>

#include "compute/ReducedOperator.h"
#include "compute/vulkan/VulkanLinearAlgebra.h"
#include "compute/vulkan/VulkanSequence.h"
#include "core/Error.h"

namespace plano::vk {
namespace {

constexpr std::uint32_t kSlice = 16;  // its SLICE: rows of the long dimension per shared-memory slice
constexpr std::uint32_t kTile = 64;  // shaders/reduced_gemm.comp's TILE: rows and columns of R per workgroup

struct SpmmPush {
  std::uint32_t vertices;
  std::uint32_t coordinates;
};

struct GemmPush {
  std::uint32_t n;
  std::uint32_t columnsA;
  std::uint32_t columnsB;
  std::uint32_t firstRow;
  std::uint32_t firstColumn;
  std::uint32_t d;
  std::uint32_t tilesB;
  std::uint32_t rowsPerChunk;
};

struct SumPush {
  std::uint32_t count;
  std::uint32_t chunks;
};

/// Split-K: rows of the long dimension per chunk at least this many (a chunk's workgroup
/// then does thousands of multiply-adds per value it writes), at most kMaxChunks chunks,
/// and the partial copies of R within the block cap.
constexpr std::size_t kMinRowsPerChunk = 2048;
constexpr std::size_t kMaxChunks = 64;

std::uint32_t tiles(std::size_t count) { return static_cast<std::uint32_t>((count + kTile - 1) / kTile); }

}  // namespace

ReducedOperatorKernel::ReducedOperatorKernel(Context& context, std::size_t blockBytes)
    : context_(context),
      blockBytes_(blockBytes > 0 ? blockBytes : kDefaultBlockBytes),
      spmm_(context, "reduced_spmm", 5, sizeof(SpmmPush)),
      gemm_(context, "reduced_gemm", 3, sizeof(GemmPush)),
      sumPartials_(context, "reduced_sum_partials", 2, sizeof(SumPush)) {}

Eigen::MatrixXd ReducedOperatorKernel::run(const compute::SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates) {
  compute::checkReducedOperatorInputs(S, N, coordinates);
  const std::size_t n = static_cast<std::size_t>(N.rows());
  const std::size_t d = static_cast<std::size_t>(N.cols());
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(N.cols(), N.cols());
  if (n == 0 || d == 0) return R;

  const DeviceInfo& info = context_.info();
  const std::size_t range = info.maxStorageBufferRange;
  const std::size_t columnBytes = n * sizeof(double);
  if (columnBytes > range || d * d * sizeof(double) > range) {
    throwDevice("Vulkan: the reduced operator of a basis of " + std::to_string(n) + " rows and " +
                std::to_string(d) + " columns exceeds the device's storage-buffer range of " + std::to_string(range) +
                " bytes; use the CPU backend");
  }
  // Columns per block: within the range and the cap, and within the workgroup counts the
  // kernels' dispatches use (the SpMM's y is the column, the GEMM's x and y its tiles).
  const std::size_t cap = std::min(range, blockBytes_);
  std::size_t perBlock = std::max<std::size_t>(1, cap / columnBytes);
  perBlock = std::min({perBlock, d, static_cast<std::size_t>(info.maxWorkGroupCount[1]),
                       std::size_t{kTile} * info.maxWorkGroupCount[0], std::size_t{kTile} * info.maxWorkGroupCount[1]});

  compute::SparseMatrix csr = S;
  csr.makeCompressed();
  const DeviceCsrMatrix deviceS(context_, csr);
  std::vector<Array<double>> blocks;
  std::vector<std::size_t> firsts;
  for (std::size_t first = 0; first < d; first += perBlock) {
    const std::size_t count = std::min(perBlock, d - first);
    blocks.emplace_back(context_, n * count, MemoryClass::Device, "basis columns");
    blocks.back().upload({N.data() + first * n, n * count});
    firsts.push_back(first);
  }
  Array<double> product(context_, n * std::min(perBlock, d), MemoryClass::Device, "operator times basis columns");
  // Chunks of the long dimension, so that a tall basis's few 64 x 64 blocks of R still make
  // enough workgroups; their partial copies of R are summed at the end.
  std::size_t chunks = std::min({(n + kMinRowsPerChunk - 1) / kMinRowsPerChunk, kMaxChunks,
                                 std::max<std::size_t>(1, cap / (d * d * sizeof(double))),
                                 std::max<std::size_t>(1, info.maxWorkGroupCount[1] / tiles(std::min(perBlock, d)))});
  const std::size_t chunkRows = ((n + chunks - 1) / chunks + kSlice - 1) / kSlice * kSlice;
  chunks = (n + chunkRows - 1) / chunkRows;  // none empty
  Array<double> result(context_, d * d, MemoryClass::Device, "reduced operator");
  Array<double> partials;
  if (chunks > 1) partials = Array<double>(context_, chunks * d * d, MemoryClass::Device, "reduced operator partial sums");
  const Array<double>& sums = chunks > 1 ? partials : result;

  const auto vertices = static_cast<std::uint32_t>(S.rows());
  Sequence sequence(context_);
  sequence.begin();
  for (std::size_t J = 0; J < blocks.size(); ++J) {
    const std::size_t columnsJ = blocks[J].count() / n;
    if (J > 0) sequence.barrier();  // the last block's products have read `product`
    sequence.dispatch(spmm_,
                      {BufferRange(deviceS.rowOffsets()), BufferRange(deviceS.columns()), BufferRange(deviceS.values()),
                       BufferRange(blocks[J]), BufferRange(product, 0, columnsJ * columnBytes)},
                      SpmmPush{vertices, static_cast<std::uint32_t>(coordinates)}, groupsFor(context_, n),
                      static_cast<std::uint32_t>(columnsJ));
    sequence.barrier();
    for (std::size_t I = 0; I < blocks.size(); ++I) {
      const std::size_t columnsI = blocks[I].count() / n;
      sequence.dispatch(gemm_, {BufferRange(blocks[I]), BufferRange(product, 0, columnsJ * columnBytes), BufferRange(sums)},
                        GemmPush{static_cast<std::uint32_t>(n), static_cast<std::uint32_t>(columnsI),
                                 static_cast<std::uint32_t>(columnsJ), static_cast<std::uint32_t>(firsts[I]),
                                 static_cast<std::uint32_t>(firsts[J]), static_cast<std::uint32_t>(d),
                                 tiles(columnsJ), static_cast<std::uint32_t>(chunkRows)},
                        tiles(columnsI), static_cast<std::uint32_t>(tiles(columnsJ) * chunks));
    }
  }
  if (chunks > 1) {
    sequence.barrier();
    sequence.dispatch(sumPartials_, {BufferRange(partials), BufferRange(result)},
                      SumPush{static_cast<std::uint32_t>(d * d), static_cast<std::uint32_t>(chunks)},
                      groupsFor(context_, d * d));
  }
  sequence.end();
  sequence.run();
  result.download({R.data(), d * d});
  return R;
}

}  // namespace plano::vk
