#include "subspace/ConstrainedSubspace.h"

#include <Eigen/Dense>
#include <string>

#include "core/Error.h"

namespace plano::subspace {

ConstrainedSubspace constrainSubspace(const SubspaceBasis& N, const PositionalConstraints& constraints,
                                      const Positions& rest, double rankTolerance) {
  const Index nv = N.vertexCount(), d = N.dimension();
  std::vector<Index> coordinates;
  std::vector<double> targets;
  auto add = [&](Index v, const Eigen::Vector3d& p) {
    if (v < 0 || v >= nv) throwBadInput("constraint on vertex " + std::to_string(v) + " out of range");
    for (int c = 0; c < 3; ++c) {
      coordinates.push_back(3 * v + c);
      targets.push_back(p[c]);
    }
  };
  for (Index v : constraints.fixed) {
    if (v < 0 || v >= nv) throwBadInput("fixed vertex " + std::to_string(v) + " out of range");
    add(v, rest.row(v).transpose());
  }
  for (const Handle& h : constraints.handles) add(h.vertex, h.position);

  ConstrainedSubspace out;
  if (coordinates.empty() || d == 0) {
    out.particular = Eigen::VectorXd::Zero(d);
    out.free = Eigen::MatrixXd::Identity(d, d);
    out.constraintResidual = coordinates.empty() ? 0.0 : Eigen::Map<const Eigen::VectorXd>(targets.data(), targets.size()).norm();
    return out;
  }
  const Eigen::MatrixXd A = N.coordinateRows(coordinates);  // C N
  const Eigen::Map<const Eigen::VectorXd> c(targets.data(), static_cast<Eigen::Index>(targets.size()));
  // (C N)^T P = Q R: the first r columns of Q span range((C N)^T), the others null(C N).
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A.transpose());
  qr.setThreshold(rankTolerance);
  const Eigen::Index r = qr.rank();
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(d, d);
  out.constraintRank = static_cast<Index>(r);
  out.free = Q.rightCols(d - r);
  const Eigen::MatrixXd Q1 = Q.leftCols(r);
  const Eigen::VectorXd y = (A * Q1).colPivHouseholderQr().solve(c);
  out.particular = Q1 * y;
  out.constraintResidual = (A * out.particular - c).norm();
  return out;
}

Positions closestInSubspace(const SubspaceBasis& N, const ConstrainedSubspace& constrained, const Positions& target) {
  const Eigen::VectorXd wanted = N.coefficients(target);
  const Eigen::VectorXd w =
      constrained.particular + constrained.free * (constrained.free.transpose() * (wanted - constrained.particular));
  return N.shape(w);
}

}  // namespace plano::subspace
