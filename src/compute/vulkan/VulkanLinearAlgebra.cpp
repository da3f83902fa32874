#include "compute/vulkan/VulkanLinearAlgebra.h"

#include <algorithm>
#include <string>
#include <utility>

#include "compute/vulkan/LinearAlgebraPushConstants.h"
#include "core/Error.h"

namespace plano::vk {
namespace {

struct BlockInversePush {
  std::uint32_t blocks, b;
};
struct MaxAbsPush {
  std::uint32_t n, terms;
  double b, c;
};
struct CountPush {
  std::uint32_t count;
};

void requireSameShape(const DeviceVectors& a, const DeviceVectors& b, const char* operation) {
  if (a.n() != b.n() || a.m() != b.m()) {
    throwUsage(std::string(operation) + ": vector blocks of " + std::to_string(a.n()) + " x " +
               std::to_string(a.m()) + " and " + std::to_string(b.n()) + " x " + std::to_string(b.m()));
  }
}

}  // namespace

std::uint32_t elementCount(std::int64_t value, const char* what) {
  if (value < 0 || value > 0x7fffffff) {
    throwDevice(std::string("Vulkan: ") + what + " of " + std::to_string(value) +
                " exceeds the 2^31 - 1 elements the kernels can index");
  }
  return static_cast<std::uint32_t>(value);
}

DeviceCsrMatrix::DeviceCsrMatrix(Context& context, const compute::SparseMatrix& A)
    : rows_(elementCount(A.rows(), "the matrix's row count")),
      cols_(elementCount(A.cols(), "the matrix's column count")),
      rowOffsets_(context, A.rows() + 1, MemoryClass::Device, "CSR row offsets"),
      columns_(context, A.nonZeros(), MemoryClass::Device, "CSR column indices"),
      values_(context, A.nonZeros(), MemoryClass::Device, "CSR values") {
  if (!A.isCompressed()) throwUsage("DeviceCsrMatrix: the matrix must be compressed (makeCompressed())");
  const std::size_t range = context.info().maxStorageBufferRange;
  if (static_cast<std::size_t>(A.nonZeros()) * sizeof(double) > range) {
    throwDevice("Vulkan: a matrix of " + std::to_string(A.nonZeros()) +
                " non-zeros exceeds the device's storage-buffer range of " + std::to_string(range) + " bytes");
  }
  rowOffsets_.upload({A.outerIndexPtr(), static_cast<std::size_t>(A.rows()) + 1});
  columns_.upload({A.innerIndexPtr(), static_cast<std::size_t>(A.nonZeros())});
  values_.upload({A.valuePtr(), static_cast<std::size_t>(A.nonZeros())});
}

DeviceVectors::DeviceVectors(Context& context, std::uint32_t n, std::uint32_t m, const char* what)
    : n_(n), m_(m), data_(context, static_cast<std::size_t>(n) * m, MemoryClass::Device, what) {
  // Column c of a block is workgroup row c of the dispatches.
  if (m > context.info().maxWorkGroupCount[1]) {
    throwDevice(std::string("Vulkan: ") + what + " has " + std::to_string(m) + " columns, more than the device's " +
                std::to_string(context.info().maxWorkGroupCount[1]) + " workgroups per dispatch row");
  }
  if (static_cast<std::size_t>(n) * m * sizeof(double) > context.info().maxStorageBufferRange) {
    throwDevice(std::string("Vulkan: ") + what + " (" + std::to_string(n) + " x " + std::to_string(m) +
                ") exceeds the device's storage-buffer range");
  }
}

void DeviceVectors::upload(const Eigen::MatrixXd& values) {
  if (values.rows() != n_ || values.cols() != m_) throwUsage("DeviceVectors::upload: shape mismatch");
  data_.upload({values.data(), static_cast<std::size_t>(values.size())});
}

void DeviceVectors::download(Eigen::MatrixXd& values) const {
  values.resize(n_, m_);
  data_.download({values.data(), static_cast<std::size_t>(values.size())});
}

DeviceScalars::DeviceScalars(Context& context, std::uint32_t slots, std::uint32_t m, std::uint32_t maxN,
                             std::uint32_t partialColumns)
    : slots_(slots),
      m_(m),
      // Each thread of the first pass sums at least four entries. At most 4096 groups keep
      // the second pass (one workgroup per column) short, and let the fused PCG product, whose
      // invocations take every column of a row, run as many invocations (262 144) as it
      // did with a row of 1024 groups per column for three columns.
      groups_(std::clamp<std::uint32_t>((maxN + 4 * kWorkGroupSize - 1) / (4 * kWorkGroupSize), 1, 4096)),
      values_(context, static_cast<std::size_t>(slots) * m, MemoryClass::Device, "device scalars"),
      partial_(context, static_cast<std::size_t>(groups_) * std::max(m, partialColumns), MemoryClass::Device,
               "partial sums") {
  groups_ = std::min(groups_, context.info().maxWorkGroupCount[0]);  // the kernels stride over the rest
}

std::vector<double> DeviceScalars::read() const {
  std::vector<double> all(static_cast<std::size_t>(slots_) * m_);
  values_.download(all);
  return all;
}

namespace {

/// The CSR of a gather: for each destination, the sources that feed it, in increasing order.
std::pair<std::vector<std::int32_t>, std::vector<std::int32_t>> gatherLists(std::span<const std::int32_t> targets,
                                                                            std::uint32_t count) {
  std::vector<std::int32_t> offsets(static_cast<std::size_t>(count) + 1, 0);
  for (const std::int32_t target : targets) {
    if (target < -1 || target >= static_cast<std::int64_t>(count)) {
      throwUsage("gather: a target " + std::to_string(target) + " outside 0 .. " + std::to_string(count) + " - 1");
    }
    if (target >= 0) ++offsets[static_cast<std::size_t>(target) + 1];
  }
  for (std::size_t i = 1; i < offsets.size(); ++i) offsets[i] += offsets[i - 1];
  std::vector<std::int32_t> indices(static_cast<std::size_t>(offsets.back()));
  std::vector<std::int32_t> next(offsets.begin(), offsets.end() - 1);
  for (std::size_t s = 0; s < targets.size(); ++s) {
    if (targets[s] >= 0) indices[static_cast<std::size_t>(next[targets[s]]++)] = static_cast<std::int32_t>(s);
  }
  return {std::move(offsets), std::move(indices)};
}

}  // namespace

DeviceGather::DeviceGather(Context& context, std::span<const std::int32_t> targets, std::uint32_t count,
                           const char* what)
    : count_(count),
      sources_(elementCount(static_cast<std::int64_t>(targets.size()), what)),
      offsets_(context, static_cast<std::size_t>(count) + 1, MemoryClass::Device, what),
      indices_(context, std::max<std::size_t>(targets.size(), 1), MemoryClass::Device, what) {
  const auto [offsets, indices] = gatherLists(targets, count);
  offsets_.upload(offsets);
  if (!indices.empty()) indices_.upload(indices);
}

LinearAlgebra::LinearAlgebra(Context& context)
    : context_(context),
      spmv_(context, "la_spmv", 5, sizeof(SpmvPush)),
      dot_(context, "la_dot", 3, sizeof(DotPush)),
      reduce_(context, "la_reduce", 2, sizeof(ReducePush)),
      axpby_(context, "la_axpby", 2, sizeof(AxpbyPush)),
      scaleRows_(context, "la_scale_rows", 3, sizeof(ScalePush)),
      clamp_(context, "la_clamp", 4, sizeof(CountPush)),
      maxAbs_(context, "la_max_abs", 4, sizeof(MaxAbsPush)),
      reduceMax_(context, "la_reduce_max", 2, sizeof(ReducePush)),
      blockInverse_(context, "block_jacobi_inverse", 5, sizeof(BlockInversePush)),
      gatherSum_(context, "la_gather_sum", 4, sizeof(CountPush)) {}

void LinearAlgebra::spmv(Sequence& sequence, const DeviceCsrMatrix& A, const DeviceVectors& X, DeviceVectors& Y) {
  if (X.n() != A.cols() || Y.n() != A.rows() || X.m() != Y.m()) {
    throwUsage("spmv: a " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) + " matrix times " +
               std::to_string(X.n()) + " x " + std::to_string(X.m()) + " into " + std::to_string(Y.n()) + " x " +
               std::to_string(Y.m()));
  }
  sequence.dispatch(spmv_, {A.rowOffsets(), A.columns(), A.values(), X.data(), Y.data()},
                    SpmvPush{A.rows(), A.cols(), X.m()}, groupsFor(context_, A.rows()));
  sequence.barrier();
}

void LinearAlgebra::dot(Sequence& sequence, const DeviceVectors& X, const DeviceVectors& Y, DeviceScalars& scalars,
                        std::uint32_t slot) {
  requireSameShape(X, Y, "dot");
  if (scalars.m() != X.m() || slot >= scalars.slots_) throwUsage("dot: scalars do not match the vectors");
  // The same number of groups for every n keeps the partial buffer's layout fixed.
  sequence.dispatch(dot_, {X.data(), Y.data(), scalars.partial_}, DotPush{X.n()}, scalars.groups_, X.m());
  sequence.barrier();
  reduce(sequence, scalars, slot);
}

void LinearAlgebra::reduce(Sequence& sequence, DeviceScalars& scalars, std::uint32_t slot) {
  if (slot >= scalars.slots_) throwUsage("reduce: slot " + std::to_string(slot) + " out of range");
  sequence.dispatch(reduce_, {scalars.partial_, scalars.values_}, ReducePush{scalars.groups_, scalars.m_, slot},
                    scalars.m_);
  sequence.barrier();
}

void LinearAlgebra::maxAbs(Sequence& sequence, const DeviceVectors& X, DeviceScalars& scalars, std::uint32_t slot) {
  maxAbs(sequence, 1, X, 0.0, X, 0.0, X, scalars, slot);
}

void LinearAlgebra::maxAbs(Sequence& sequence, const DeviceVectors& X, double b, const DeviceVectors& Y,
                           DeviceScalars& scalars, std::uint32_t slot) {
  maxAbs(sequence, 2, X, b, Y, 0.0, Y, scalars, slot);
}

void LinearAlgebra::maxAbs(Sequence& sequence, const DeviceVectors& X, double b, const DeviceVectors& Y, double c,
                           const DeviceVectors& Z, DeviceScalars& scalars, std::uint32_t slot) {
  maxAbs(sequence, 3, X, b, Y, c, Z, scalars, slot);
}

void LinearAlgebra::maxAbs(Sequence& sequence, std::uint32_t terms, const DeviceVectors& X, double b,
                           const DeviceVectors& Y, double c, const DeviceVectors& Z, DeviceScalars& scalars,
                           std::uint32_t slot) {
  requireSameShape(X, Y, "maxAbs");
  requireSameShape(X, Z, "maxAbs");
  if (scalars.m() != X.m() || slot >= scalars.slots_) throwUsage("maxAbs: scalars do not match the vectors");
  sequence.dispatch(maxAbs_, {X.data(), Y.data(), Z.data(), scalars.partial_}, MaxAbsPush{X.n(), terms, b, c},
                    scalars.groups_, X.m());
  sequence.barrier();
  sequence.dispatch(reduceMax_, {scalars.partial_, scalars.values_}, ReducePush{scalars.groups_, scalars.m_, slot},
                    scalars.m_);
  sequence.barrier();
}

void LinearAlgebra::axpby(Sequence& sequence, double a, const DeviceVectors& X, double b, DeviceVectors& Y) {
  requireSameShape(X, Y, "axpby");
  const std::uint32_t count = X.n() * X.m();
  sequence.dispatch(axpby_, {X.data(), Y.data()}, AxpbyPush{count, 0, a, b}, sweepGroupsFor(context_, count));
  sequence.barrier();
}

void LinearAlgebra::scaleRows(Sequence& sequence, const Array<double>& d, const DeviceVectors& X, DeviceVectors& Y) {
  applyBlockDiagonal(sequence, d, 1, X, Y);
}

void LinearAlgebra::applyBlockDiagonal(Sequence& sequence, const Array<double>& blocks, std::uint32_t b,
                                       const DeviceVectors& X, DeviceVectors& Y) {
  requireSameShape(X, Y, "applyBlockDiagonal");
  if (b == 0 || X.n() % b != 0 || blocks.count() != static_cast<std::size_t>(X.n()) * b) {
    throwUsage("applyBlockDiagonal: " + std::to_string(blocks.count()) + " block entries for " +
               std::to_string(X.n()) + " rows in blocks of " + std::to_string(b));
  }
  sequence.dispatch(scaleRows_, {blocks, X.data(), Y.data()}, ScalePush{X.n(), X.m(), b},
                    sweepGroupsFor(context_, static_cast<std::size_t>(X.n()) * X.m()));
  sequence.barrier();
}

void LinearAlgebra::invertDiagonalBlocks(Sequence& sequence, const DeviceCsrMatrix& A, std::uint32_t b,
                                         Array<double>& inverses, Array<std::uint32_t>& failure) {
  if (b < 1 || b > 4 || A.rows() != A.cols() || A.rows() % b != 0 ||
      inverses.count() != static_cast<std::size_t>(A.rows()) * b || failure.count() < 1) {
    throwUsage("invertDiagonalBlocks: " + std::to_string(A.rows()) + "x" + std::to_string(A.cols()) +
               " matrix, blocks of " + std::to_string(b) + ", " + std::to_string(inverses.count()) +
               " block entries (need a square matrix, 1 to 4 rows per block dividing its rows, rows x b entries)");
  }
  const std::uint32_t blocks = A.rows() / b;
  sequence.dispatch(blockInverse_, {A.rowOffsets(), A.columns(), A.values(), inverses, failure},
                    BlockInversePush{blocks, b}, groupsFor(context_, blocks));
  sequence.barrier();
}

void LinearAlgebra::clamp(Sequence& sequence, const DeviceVectors& X, const DeviceVectors& L, const DeviceVectors& U,
                          DeviceVectors& Y) {
  requireSameShape(X, L, "clamp");
  requireSameShape(X, U, "clamp");
  requireSameShape(X, Y, "clamp");
  const std::uint32_t count = X.n() * X.m();
  sequence.dispatch(clamp_, {X.data(), L.data(), U.data(), Y.data()}, CountPush{count}, sweepGroupsFor(context_, count));
  sequence.barrier();
}

void LinearAlgebra::gatherSum(Sequence& sequence, const DeviceGather& gather, const Array<double>& source,
                              Array<double>& destination) {
  if (source.count() < gather.sources() || destination.count() < gather.count()) {
    throwUsage("gatherSum: " + std::to_string(source.count()) + " source and " + std::to_string(destination.count()) +
               " destination values for a map of " + std::to_string(gather.sources()) + " to " +
               std::to_string(gather.count()));
  }
  sequence.dispatch(gatherSum_, {gather.offsets(), gather.indices(), source, destination}, CountPush{gather.count()},
                    groupsFor(context_, gather.count()));
  sequence.barrier();
}

void LinearAlgebra::copy(Sequence& sequence, const DeviceVectors& X, DeviceVectors& Y) {
  requireSameShape(X, Y, "copy");
  sequence.copy(X.data(), Y.data(), static_cast<std::size_t>(X.n()) * X.m() * sizeof(double));
  sequence.barrier();
}

}  // namespace plano::vk
