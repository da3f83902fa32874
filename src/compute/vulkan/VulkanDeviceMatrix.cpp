#include "compute/vulkan/VulkanDeviceMatrix.h"

#include <atomic>
#include <vector>

#include "core/Error.h"

namespace plano::vk {

std::uint64_t nextArrayGeneration() {
  static std::atomic<std::uint64_t> last{0};
  return ++last;
}

ArraySource::ArraySource(const Context& context, const Array<double>& array, ArrayLayout layout, Eigen::Index rows,
                         Eigen::Index cols, std::uint64_t generation, std::weak_ptr<const std::uint64_t> live)
    : context_(context), array_(array), layout_(layout), rows_(rows), cols_(cols), generation_(generation),
      live_(std::move(live)) {}

bool ArraySource::current() const {
  const auto live = live_.lock();
  return live && *live == generation_;
}

void ArraySource::fetch(Eigen::MatrixXd& out) const {
  if (!current()) {
    throwUsage("device matrix: its device array was rewritten (or freed) before its values were read");
  }
  const Eigen::Index stored = layout_ == ArrayLayout::FaceMapColumns ? 4 * rows_ : rows_ * cols_;
  std::vector<double> values(static_cast<std::size_t>(stored));
  if (!values.empty()) array_.download(values);
  out.resize(rows_, cols_);
  switch (layout_) {
    case ArrayLayout::ColumnMajor: out = Eigen::Map<const Eigen::MatrixXd>(values.data(), rows_, cols_); break;
    case ArrayLayout::RowMajor:
      out = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(values.data(),
                                                                                                   rows_, cols_);
      break;
    case ArrayLayout::FaceMapColumns:
      for (Eigen::Index f = 0; 4 * f < rows_; ++f) {
        out.middleRows<4>(4 * f) = Eigen::Map<const Eigen::Matrix4d>(values.data() + 16 * f).leftCols(cols_);
      }
      break;
  }
}

const Array<double>* ArraySource::arrayIn(const Context& context) const {
  return &context == &context_ && current() ? &array_ : nullptr;
}

const ArraySource* arraySourceOf(const compute::DeviceMatrix& m, const Context& context, ArrayLayout layout) {
  const auto* source = dynamic_cast<const ArraySource*>(m.source());
  return source && source->layout() == layout && source->arrayIn(context) ? source : nullptr;
}

const Array<double>* arrayOf(const compute::DeviceMatrix& m, const Context& context, ArrayLayout layout) {
  const ArraySource* source = m.factor() == 1.0 ? arraySourceOf(m, context, layout) : nullptr;
  return source ? source->arrayIn(context) : nullptr;
}

}  // namespace plano::vk
