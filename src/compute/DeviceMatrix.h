#pragma once
// A dense matrix whose values may stay on the device of the backend that computed them.
// Host code that reads values() copies them over once; a kernel of that backend recognises
// the matrix's source and binds the device copy instead. A loop written once against the
// backend interface (projective deformation: the local step's ideal maps, the global step's
// linear term and warm start) then moves no mesh-sized data between steps that both run on
// the device, and stays correct wherever a step needs the values on the host.
#include <Eigen/Core>
#include <memory>
#include <optional>

namespace plano::compute {

/// Where a DeviceMatrix's values are kept: one implementation per kind of device array.
class DeviceMatrixSource {
 public:
  virtual ~DeviceMatrixSource() = default;
  /// Copy the values over (rows x cols, unscaled). Throws Error(Usage) when the device no
  /// longer holds them (its array was rewritten since).
  virtual void fetch(Eigen::MatrixXd& out) const = 0;
};

class DeviceMatrix {
 public:
  /// 0 x 0 values on the host.
  DeviceMatrix() : host_(std::in_place) {}
  /// Values on the host (implicit: every function that takes a DeviceMatrix takes an
  /// Eigen matrix as before).
  DeviceMatrix(Eigen::MatrixXd values);  // NOLINT(google-explicit-constructor)
  /// Host values of any Eigen expression (Zero, a product, ...).
  template <class Derived>
  DeviceMatrix(const Eigen::MatrixBase<Derived>& values)  // NOLINT(google-explicit-constructor)
      : DeviceMatrix(Eigen::MatrixXd(values)) {}
  /// factor times the rows x cols matrix `source` keeps.
  DeviceMatrix(Eigen::Index rows, Eigen::Index cols, std::shared_ptr<const DeviceMatrixSource> source,
               double factor = 1.0);

  Eigen::Index rows() const { return rows_; }
  Eigen::Index cols() const { return cols_; }
  Eigen::Index size() const { return rows_ * cols_; }

  /// The values; copied over from the source on the first call (not thread-safe).
  const Eigen::MatrixXd& values() const;
  /// Whether values() costs no copy.
  bool onHost() const { return !source_ || host_.has_value(); }

  /// The device copy, or null for host values: a backend's kernels bind source()'s array
  /// (times factor()) when it is theirs.
  const DeviceMatrixSource* source() const { return source_.get(); }
  double factor() const { return factor_; }

  /// -this, sharing the source (no copy anywhere).
  DeviceMatrix negated() const;

 private:
  Eigen::Index rows_ = 0;
  Eigen::Index cols_ = 0;
  std::shared_ptr<const DeviceMatrixSource> source_;
  double factor_ = 1.0;
  mutable std::optional<Eigen::MatrixXd> host_;
};

}  // namespace plano::compute
