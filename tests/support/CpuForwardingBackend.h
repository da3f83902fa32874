#pragma once
// A test backend that forwards every operation to the CPU reference; tests derive from it
// and override the one operation they instrument or replace (e.g. an iterative SPD solver,
// a recording ADMM).
#include "compute/cpu/CpuBackend.h"

namespace plano::test {

class CpuForwardingBackend : public compute::Backend {
 public:
  compute::BackendKind kind() const override { return compute::BackendKind::Cpu; }
  void facePlanarity(const PolygonMesh& mesh, std::span<double> out) override { cpu_.facePlanarity(mesh, out); }
  void fitProjectiveMaps(const FaceList& faces, const Positions& source, const Positions& target,
                         compute::ProjectiveFits& out) override {
    cpu_.fitProjectiveMaps(faces, source, target, out);
  }
  void closestRotations(std::span<const Eigen::Matrix3d> matrices, std::span<Eigen::Matrix3d> rotations,
                        std::span<Eigen::Vector3d> singularValues) override {
    cpu_.closestRotations(matrices, rotations, singularValues);
  }
  void closestIdealMaps(const FaceList& faces, const Positions& source, std::span<const Eigen::Matrix4d> fitted,
                        const Positions* target, bool similar, compute::IdealMaps& out) override {
    cpu_.closestIdealMaps(faces, source, fitted, target, similar, out);
  }
  std::unique_ptr<compute::SpdSolver> createSpdSolver(const compute::SparseMatrix& A,
                                                      const compute::LinearSolverSettings& settings) override {
    return cpu_.createSpdSolver(A, settings);
  }
  bool factorsSpdMatrices() const override { return cpu_.factorsSpdMatrices(); }

 protected:
  compute::CpuBackend cpu_;
};

}  // namespace plano::test
