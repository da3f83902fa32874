#include "compute/DeviceMatrix.h"

#include <string>

#include "core/Error.h"

namespace plano::compute {

DeviceMatrix::DeviceMatrix(Eigen::MatrixXd values)
    : rows_(values.rows()), cols_(values.cols()), host_(std::move(values)) {}

DeviceMatrix::DeviceMatrix(Eigen::Index rows, Eigen::Index cols, std::shared_ptr<const DeviceMatrixSource> source,
                           double factor)
    : rows_(rows), cols_(cols), source_(std::move(source)), factor_(factor) {
  if (rows < 0 || cols < 0) throwUsage("device matrix: negative size");
  if (!source_) throwUsage("device matrix: no source");
}

const Eigen::MatrixXd& DeviceMatrix::values() const {
  if (!host_) {
    Eigen::MatrixXd fetched;
    source_->fetch(fetched);
    if (fetched.rows() != rows_ || fetched.cols() != cols_) {
      throwUsage("device matrix: its source holds " + std::to_string(fetched.rows()) + " x " +
                 std::to_string(fetched.cols()) + " values, not " + std::to_string(rows_) + " x " +
                 std::to_string(cols_));
    }
    // Exact for the factors used (+-1): the fetched matrix is the one the device's kernels read.
    if (factor_ != 1.0) fetched *= factor_;
    host_ = std::move(fetched);
  }
  return *host_;
}

DeviceMatrix DeviceMatrix::negated() const {
  if (!source_) return DeviceMatrix(Eigen::MatrixXd(-*host_));
  DeviceMatrix result(rows_, cols_, source_, -factor_);
  if (host_) result.host_ = Eigen::MatrixXd(-*host_);
  return result;
}

}  // namespace plano::compute
