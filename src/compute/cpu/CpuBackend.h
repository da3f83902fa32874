#pragma once
// The CPU reference backend: Eigen, one face at a time (the batched per-face kernels split
// the faces over core/ParallelFor.h's threads, cpuThreads(); every face's result is the same
// whatever their count), a prefactored sparse Cholesky (CHOLMOD) for the SPD solves. Every
// Vulkan kernel is checked against it.
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

 private:
  /// One matrix's closest rotation (closestRotations' work per item).
  static void closestRotation(const Eigen::Matrix3d& matrix, Eigen::Matrix3d& rotation, Eigen::Vector3d& singularValues);
};

}  // namespace plano::compute
