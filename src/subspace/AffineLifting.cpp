#include "subspace/AffineLifting.h"

#include <Eigen/Dense>
#include <string>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "subspace/LinearSpace.h"
#include "subspace/MeshLaplacian.h"
#include "subspace/SubspaceTopology.h"

namespace plano::subspace {

PolygonMesh liftWithAffineSpace(compute::Backend& backend, const PolygonMesh& flat, const LiftSettings& settings,
                                LiftInfo* info) {
  const Index nv = flat.vertexCount();
  const double diagonal = boundingBoxDiagonal(flat.vertices);
  if (!(diagonal > 0.0)) throwBadInput("lifting: the mesh has no extent");
  if (flat.vertices.col(2).cwiseAbs().maxCoeff() > 1e-9 * diagonal) throwBadInput("lifting: the mesh is not flat (z != 0)");
  const LinearSpace space = buildLinearSpace(flat, uniformAssignment(SpaceKind::Affine, flat.faceCount()));
  const Eigen::MatrixXd& N1 = space.N.columns();  // Scalar liftings, including 1, x and y.
  Eigen::MatrixXd planar(nv, 3);
  planar << Eigen::VectorXd::Ones(nv), flat.vertices.col(0), flat.vertices.col(1);
  const Eigen::MatrixXd Q = planar.householderQr().householderQ() * Eigen::MatrixXd::Identity(nv, 3);
  const Eigen::MatrixXd rest = N1 - Q * (Q.transpose() * N1);
  Eigen::BDCSVD<Eigen::MatrixXd> svd(rest, Eigen::ComputeThinU);
  Eigen::Index liftings = 0;
  while (liftings < svd.singularValues().size() && svd.singularValues()[liftings] > 1e-8) ++liftings;
  if (liftings == 0) {
    throwNumerical("lifting: this topology only has planar liftings (its affine space is " +
                   std::to_string(space.N.dimension()) + "-dimensional, the global affine maps)");
  }
  const Eigen::MatrixXd M = svd.matrixU().leftCols(liftings);  // Orthonormal non-planar liftings.
  Eigen::VectorXd h;
  if (settings.kind == LiftKind::Eigenshape) {
    if (settings.eigenshape < 0 || settings.eigenshape >= liftings) {
      throwUsage("lifting: eigenshape " + std::to_string(settings.eigenshape) + " out of range (" +
                 std::to_string(liftings) + " non-planar liftings)");
    }
    const Eigen::MatrixXd R = backend.reducedOperator(uniformLaplacian(flat.faces, nv), M, 1);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (R + R.transpose()));
    h = M * eig.eigenvectors().col(settings.eigenshape);
  } else {
    Index handle = settings.handleVertex;
    if (handle < 0) {
      const Eigen::RowVector3d centroid = flat.vertices.colwise().mean();
      (flat.vertices.rowwise() - centroid).rowwise().squaredNorm().minCoeff(&handle);
    }
    if (handle >= nv) throwBadInput("lifting: handle vertex " + std::to_string(handle) + " out of range");
    // Boundary at height 0, the handle at 1, in the least-squares sense over the liftings.
    const SubspaceTopology t = computeTopology(flat.faces, nv);
    std::vector<Index> rows;
    for (const auto& loop : t.boundaryLoops) rows.insert(rows.end(), loop.begin(), loop.end());
    rows.push_back(handle);
    Eigen::MatrixXd A(rows.size(), liftings);
    Eigen::VectorXd c = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(rows.size()));
    for (std::size_t i = 0; i < rows.size(); ++i) A.row(i) = M.row(rows[i]);
    c[c.size() - 1] = 1.0;
    h = M * A.completeOrthogonalDecomposition().solve(c);
  }
  const double peak = h.cwiseAbs().maxCoeff();
  if (!(peak > 0.0)) throwNumerical("lifting: the chosen lifting is zero");
  if (h.maxCoeff() < -h.minCoeff()) h = -h;  // Upwards.
  PolygonMesh lifted = flat;
  lifted.vertices.col(2) = (settings.height * diagonal / peak) * h;
  if (info) {
    info->liftings = static_cast<Index>(liftings);
    info->maxHeight = lifted.vertices.col(2).cwiseAbs().maxCoeff();
  }
  return lifted;
}

PolygonMesh liftWithAffineSpace(const PolygonMesh& flat, const LiftSettings& settings, LiftInfo* info) {
  compute::CpuBackend cpu;
  return liftWithAffineSpace(cpu, flat, settings, info);
}

}  // namespace plano::subspace
