#pragma once
// The sources of the device matrices (compute::DeviceMatrix) whose values one device array
// holds: kernels of the same context bind that array instead of uploading the values.
#include <cstddef>
#include <cstdint>
#include <memory>

#include "compute/DeviceMatrix.h"
#include "compute/vulkan/VulkanBuffer.h"

namespace plano::vk {

/// One face map in a device array: 16 doubles, column-major (the fit and ideal-map kernels').
inline constexpr std::size_t kFaceMapBytes = 16 * sizeof(double);

/// A generation no array of this process has had before (never 0): the owners of device
/// arrays give their contents such generations, so that one generation names one content.
std::uint64_t nextArrayGeneration();

/// How an array holds a rows x cols matrix.
enum class ArrayLayout {
  ColumnMajor,  ///< Entry (r, c) at c * rows + r (DeviceVectors: the ADMM's x).
  RowMajor,     ///< Entry (r, c) at r * cols + c (vertex positions, as Positions).
  /// The first three columns of 4x4 face maps stored 16 doubles a face, column-major:
  /// entry (4 f + r, c) at 16 f + 4 c + r (the ideal-map kernel's array; rows = 4 #F, cols 3).
  FaceMapColumns,
};

/// A device matrix's values in one array of a context, valid while the array's owner keeps
/// the generation the source was made for (watched weakly: the owner may be gone).
class ArraySource final : public compute::DeviceMatrixSource {
 public:
  ArraySource(const Context& context, const Array<double>& array, ArrayLayout layout, Eigen::Index rows,
              Eigen::Index cols, std::uint64_t generation, std::weak_ptr<const std::uint64_t> live);
  void fetch(Eigen::MatrixXd& out) const override;
  /// The array when it still holds the values and belongs to `context`; else null.
  const Array<double>* arrayIn(const Context& context) const;
  ArrayLayout layout() const { return layout_; }
  std::uint64_t generation() const { return generation_; }

 private:
  bool current() const;
  const Context& context_;
  const Array<double>& array_;
  ArrayLayout layout_;
  Eigen::Index rows_, cols_;
  std::uint64_t generation_;
  std::weak_ptr<const std::uint64_t> live_;
};

/// The source of `m` when it is an ArraySource of `context` in `layout`, still current
/// (whatever m's factor); else null.
const ArraySource* arraySourceOf(const compute::DeviceMatrix& m, const Context& context, ArrayLayout layout);

/// The array of `m` when its source is an ArraySource of `context` in `layout`, still
/// current, with factor 1; else null.
const Array<double>* arrayOf(const compute::DeviceMatrix& m, const Context& context, ArrayLayout layout);

}  // namespace plano::vk
