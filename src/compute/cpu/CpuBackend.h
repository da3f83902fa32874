#pragma once
// The CPU reference backend: Eigen, one face at a time, a prefactored sparse Cholesky
// (CHOLMOD) for the SPD solves. Every Vulkan kernel is checked against it.
#include "compute/Backend.h"

namespace plano::compute {

class CpuBackend final : public Backend {
 public:
  BackendKind kind() const override { return BackendKind::Cpu; }
  std::string name() const override { return "cpu"; }

  void facePlanarity(const PolygonMesh& mesh, std::span<double> out) override;
  void fitProjectiveMaps(const FaceList& faces, const Positions& source, const Positions& target,
                         ProjectiveFits& out) override;
  void closestRotations(std::span<const Eigen::Matrix3d> matrices, std::span<Eigen::Matrix3d> rotations,
                        std::span<Eigen::Vector3d> singularValues) override;
  void closestIdealMaps(const FaceList& faces, const Positions& source, std::span<const Eigen::Matrix4d> fitted,
                        const Positions* target, bool similar, IdealMaps& out) override;
  std::unique_ptr<SpdSolver> createSpdSolver(const SparseMatrix& A, const LinearSolverSettings& settings) override;
  bool factorsSpdMatrices() const override { return true; }  ///< CHOLMOD
};

}  // namespace plano::compute
