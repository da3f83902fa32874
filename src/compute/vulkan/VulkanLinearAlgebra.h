#pragma once
// Sparse and dense linear algebra on the device, the building blocks of the global steps
// (the PCG solve here, a device ADMM later): CSR matrix-vector products, column-wise dot
// products and inf-norms with two-pass workgroup reductions, axpby, row scaling and box projection.
//
// Vectors come in blocks of m columns of n entries (column-major), so that the three
// coordinates of a mesh-sized unknown are one dispatch. Operations are *recorded* into a
// Sequence (each followed by a barrier) and run when the sequence runs; scalars such as
// dot products stay on the device in DeviceScalars until the host asks for them.
#include <cstdint>
#include <span>
#include <vector>

#include "compute/Backend.h"
#include "compute/vulkan/VulkanSequence.h"

namespace plano::vk {

/// `value` as a kernel's element count: the shaders index with 32-bit signed integers,
/// so counts above 2^31 - 1 (or negative) are Error(Device) naming `what`.
std::uint32_t elementCount(std::int64_t value, const char* what);

/// A compressed-row matrix on the device (uploaded once).
class DeviceCsrMatrix {
 public:
  /// Upload A (compressed; throws Error(Device) when a buffer exceeds the device's range).
  DeviceCsrMatrix(Context& context, const compute::SparseMatrix& A);
  std::uint32_t rows() const { return rows_; }
  std::uint32_t cols() const { return cols_; }
  const Array<std::int32_t>& rowOffsets() const { return rowOffsets_; }
  const Array<std::int32_t>& columns() const { return columns_; }
  const Array<double>& values() const { return values_; }
  /// For new values on the same pattern (uploaded, or written by a kernel).
  Array<double>& values() { return values_; }

 private:
  std::uint32_t rows_;
  std::uint32_t cols_;
  Array<std::int32_t> rowOffsets_;
  Array<std::int32_t> columns_;
  Array<double> values_;
};

/// A fixed sparse map between value arrays (LinearAlgebra::gatherSum), on the device:
/// destination[i] = the sum of source[s] over the s with targets[s] == i, in increasing s.
/// Made once from a pattern, applied to new values on the device (a coarse matrix's values
/// from a fine one's, a transpose's from its matrix's).
class DeviceGather {
 public:
  /// `targets`: one entry per source value, in 0 .. count - 1, or -1 where it feeds nothing.
  DeviceGather(Context& context, std::span<const std::int32_t> targets, std::uint32_t count, const char* what);
  std::uint32_t count() const { return count_; }
  std::size_t sources() const { return sources_; }
  const Array<std::int32_t>& offsets() const { return offsets_; }
  const Array<std::int32_t>& indices() const { return indices_; }

 private:
  std::uint32_t count_;
  std::size_t sources_;
  Array<std::int32_t> offsets_;
  Array<std::int32_t> indices_;
};

/// m column vectors of n entries each, column-major, on the device.
class DeviceVectors {
 public:
  DeviceVectors(Context& context, std::uint32_t n, std::uint32_t m, const char* what);
  std::uint32_t n() const { return n_; }
  std::uint32_t m() const { return m_; }
  Array<double>& data() { return data_; }
  const Array<double>& data() const { return data_; }
  /// Upload / download an n x m Eigen matrix (sizes must match).
  void upload(const Eigen::MatrixXd& values);
  void download(Eigen::MatrixXd& values) const;

 private:
  std::uint32_t n_;
  std::uint32_t m_;
  Array<double> data_;
};

/// `slots` x m scalars on the device (slot s of column c at s * m + c), plus the scratch
/// of the dot products' first pass for vectors of up to maxN entries.
class DeviceScalars {
 public:
  /// `partialColumns` (default m): columns of first-pass partial sums, for fused kernels
  /// that produce two quantities per column.
  DeviceScalars(Context& context, std::uint32_t slots, std::uint32_t m, std::uint32_t maxN,
                std::uint32_t partialColumns = 0);
  std::uint32_t m() const { return m_; }
  /// Copy all slots to the host (after the sequence that wrote them ran).
  std::vector<double> read() const;
  double at(const std::vector<double>& all, std::uint32_t slot, std::uint32_t column) const {
    return all[slot * m_ + column];
  }
  /// The device buffer, for kernels that read scalars (e.g. PCG step lengths).
  const Array<double>& values() const { return values_; }
  /// First-pass scratch and its workgroup count, for fused kernels that produce partial
  /// sums themselves (finished with LinearAlgebra::reduce).
  const Array<double>& partial() const { return partial_; }
  std::uint32_t groups() const { return groups_; }

 private:
  friend class LinearAlgebra;
  std::uint32_t slots_;
  std::uint32_t m_;
  std::uint32_t groups_;  ///< Workgroups (partial sums per column) of the first pass.
  Array<double> values_;
  Array<double> partial_;
};

class LinearAlgebra {
 public:
  /// Builds the pipelines (once).
  explicit LinearAlgebra(Context& context);

  /// Y = A X (X: A.cols x m, Y: A.rows x m).
  void spmv(Sequence& sequence, const DeviceCsrMatrix& A, const DeviceVectors& X, DeviceVectors& Y);
  /// scalars[slot][c] = X(:, c) . Y(:, c).
  void dot(Sequence& sequence, const DeviceVectors& X, const DeviceVectors& Y, DeviceScalars& scalars,
           std::uint32_t slot);
  /// Second pass of a dot product whose partial sums are already in scalars.partial():
  /// scalars[slot][c] = sum of the column's partial sums.
  void reduce(Sequence& sequence, DeviceScalars& scalars, std::uint32_t slot);
  /// scalars[slot][c] = ||X(:, c)||_inf, ||X(:, c) + b Y(:, c)||_inf or
  /// ||X(:, c) + b Y(:, c) + c Z(:, c)||_inf (max-abs reductions; NaN propagates).
  void maxAbs(Sequence& sequence, const DeviceVectors& X, DeviceScalars& scalars, std::uint32_t slot);
  void maxAbs(Sequence& sequence, const DeviceVectors& X, double b, const DeviceVectors& Y, DeviceScalars& scalars,
              std::uint32_t slot);
  void maxAbs(Sequence& sequence, const DeviceVectors& X, double b, const DeviceVectors& Y, double c,
              const DeviceVectors& Z, DeviceScalars& scalars, std::uint32_t slot);
  /// Y = a X + b Y.
  void axpby(Sequence& sequence, double a, const DeviceVectors& X, double b, DeviceVectors& Y);
  /// Y = diag(d) X, d of n entries applied to every column.
  void scaleRows(Sequence& sequence, const Array<double>& d, const DeviceVectors& X, DeviceVectors& Y);
  /// Y = blockdiag(M) X: `blocks` holds n / b dense b x b blocks, row-major, block i
  /// acting on rows b i .. b i + b - 1 of every column (b = 1: scaleRows).
  void applyBlockDiagonal(Sequence& sequence, const Array<double>& blocks, std::uint32_t b, const DeviceVectors& X,
                          DeviceVectors& Y);
  /// `inverses` = the inverses of A's b x b diagonal blocks (b = 1 to 4; block j is rows
  /// and columns b j .. b j + b - 1), row-major as applyBlockDiagonal reads them: the
  /// block-Jacobi preconditioner, computed from each block's Cholesky factor where A is.
  /// A block that is not positive definite or not finite gets zeros and leaves its index
  /// in failure[0], which must hold ~0u when the sequence runs (the smallest index wins).
  void invertDiagonalBlocks(Sequence& sequence, const DeviceCsrMatrix& A, std::uint32_t b, Array<double>& inverses,
                            Array<std::uint32_t>& failure);
  /// Y = min(max(X, L), U) entry by entry.
  void clamp(Sequence& sequence, const DeviceVectors& X, const DeviceVectors& L, const DeviceVectors& U,
             DeviceVectors& Y);
  /// Y = X (a device copy).
  void copy(Sequence& sequence, const DeviceVectors& X, DeviceVectors& Y);
  /// destination = gather applied to source (DeviceGather).
  void gatherSum(Sequence& sequence, const DeviceGather& gather, const Array<double>& source,
                 Array<double>& destination);

  Context& context() { return context_; }

 private:
  void maxAbs(Sequence& sequence, std::uint32_t terms, const DeviceVectors& X, double b, const DeviceVectors& Y,
              double c, const DeviceVectors& Z, DeviceScalars& scalars, std::uint32_t slot);

  Context& context_;
  Pipeline spmv_;
  Pipeline dot_;
  Pipeline reduce_;
  Pipeline axpby_;
  Pipeline scaleRows_;
  Pipeline clamp_;
  Pipeline maxAbs_;
  Pipeline reduceMax_;
  Pipeline blockInverse_;
  Pipeline gatherSum_;
};

}  // namespace plano::vk
