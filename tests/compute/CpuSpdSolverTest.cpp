// The CPU backend's prefactored Cholesky (CHOLMOD).
#include <gtest/gtest.h>

#include <limits>

#include "compute/MeshMatrices.h"
#include "compute/cpu/CpuBackend.h"
#include "mesh/Generators.h"

namespace plano::test {
namespace {

struct System {
  compute::SparseMatrix A;
  Eigen::MatrixXd B;
};

System meshSystem() {
  const PolygonMesh mesh = generate::translationalSurface(12, 12);
  return {laplacianLikeSpd(mesh, 0.01), mesh.vertices};
}

TEST(CpuSpdSolver, MeasuresTheRelativeResidualByDefault) {
  const System s = meshSystem();
  auto solver = compute::CpuBackend().createSpdSolver(s.A, {});
  Eigen::MatrixXd X;
  const compute::LinearSolveInfo info = solver->solve(s.B, X);
  EXPECT_TRUE(info.converged);
  EXPECT_EQ(info.iterations, 1);
  EXPECT_GT(info.relativeResidual, 0.0);  // rounding, measured
  EXPECT_LT(info.relativeResidual, 1e-12);
}

TEST(CpuSpdSolver, WithoutTheResidualItGivesTheSameSolutionAndStillFlagsNonFiniteOnes) {
  const System s = meshSystem();
  compute::CpuBackend cpu;
  auto measured = cpu.createSpdSolver(s.A, {});
  compute::LinearSolverSettings settings;
  settings.measureResidual = false;
  auto unmeasured = cpu.createSpdSolver(s.A, settings);
  Eigen::MatrixXd X, Y;
  measured->solve(s.B, X);
  const compute::LinearSolveInfo info = unmeasured->solve(s.B, Y);
  EXPECT_TRUE(info.converged);
  EXPECT_EQ(info.relativeResidual, 0.0);
  EXPECT_EQ(X, Y);

  Eigen::MatrixXd bad = s.B;
  bad(3, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(unmeasured->solve(bad, Y).converged);
  EXPECT_FALSE(measured->solve(bad, X).converged);
}

}  // namespace
}  // namespace plano::test
