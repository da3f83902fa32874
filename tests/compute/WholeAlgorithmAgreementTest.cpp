// Whole algorithms on the Vulkan backend against the CPU reference: the same mesh to
// 1e-6 of the bounding-box diagonal and the same iteration counts. The kernels agree to
// 1e-10 (their own tests); these check that nothing in an algorithm depends on which
// backend runs it (solver tolerances, iterative vs direct solves, warm starts).
// Cube subdivision and multires deformation are not checked here: on lavapipe their
// thousands of ε-relaxed ADMM iterations take minutes, too long for the suite.
#include <gtest/gtest.h>

#include <cstdlib>

#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"
#include "mesh/Generators.h"
#include "projective/Deformation.h"
#include "subspace/LinearSpace.h"
#include "subspace/SubspaceDeformation.h"
#include "subspace/SubspaceTopology.h"

namespace plano::test {
namespace {

/// The agreement the project promises between backends, relative to the bounding-box diagonal.
constexpr double kAgreement = 1e-6;

double relativeDifference(const Positions& a, const Positions& b) {
  EXPECT_EQ(a.rows(), b.rows());
  if (a.rows() != b.rows()) return INFINITY;
  return (a - b).rowwise().norm().maxCoeff() / boundingBoxDiagonal(b);
}

using WholeAlgorithmAgreement = VulkanTest;

TEST_F(WholeAlgorithmAgreement, SingleLevelDeformationGivesTheCpuMeshWithTheSameIterations) {
  const Index n = 4;
  const PolygonMesh grid = generate::translationalSurface(n, n);
  PositionalConstraints constraints;
  for (Index i = 0; i <= n; ++i) constraints.fixed.push_back(i * (n + 1));
  const Index corner = n * (n + 1) + n;
  constraints.handles.push_back({corner, grid.vertices.row(corner).transpose() + Eigen::Vector3d(0.1, 0.1, 0.3)});
  compute::CpuBackend cpu;
  const projective::DeformationResult reference = projective::deform(cpu, grid, constraints);
  const projective::DeformationResult result = projective::deform(backend(), grid, constraints);
  ASSERT_EQ(reference.info.status, projective::DeformationStatus::Converged);
  EXPECT_EQ(result.info.status, reference.info.status);
  EXPECT_EQ(result.info.iterations, reference.info.iterations);
  EXPECT_LT(relativeDifference(result.mesh.vertices, reference.mesh.vertices), kAgreement);
  EXPECT_LT(result.info.planarity.max, 1e-6);
}

TEST_F(WholeAlgorithmAgreement, SubspaceDeformationGivesTheCpuMeshWithTheSameIterations) {
  const PolygonMesh dome = generate::hexagonalDome(3);
  const subspace::LinearSpace space = subspace::buildLinearSpace(
      dome, subspace::uniformAssignment(subspace::SpaceKind::Vertical, dome.faceCount()));
  const subspace::SubspaceTopology topology = subspace::computeTopology(dome.faces, dome.vertexCount());
  PositionalConstraints constraints;
  for (const auto& loop : topology.boundaryLoops) constraints.fixed.insert(constraints.fixed.end(), loop.begin(), loop.end());
  Index top = 0;
  dome.vertices.col(2).maxCoeff(&top);
  const double lift = 0.05 * boundingBoxDiagonal(dome.vertices);
  constraints.handles.push_back({top, dome.vertices.row(top).transpose() + Eigen::Vector3d(0, 0, lift)});

  for (const subspace::DeformationEnergy energy : {subspace::DeformationEnergy::Asap, subspace::DeformationEnergy::Arap}) {
    subspace::SubspaceDeformationSettings settings;
    settings.energy = energy;
    settings.maxIterations = 30;
    compute::CpuBackend cpu;
    Positions reference = dome.vertices, result = dome.vertices;
    const auto referenceInfo = subspace::SubspaceDeformer(space, constraints, cpu, settings).solve(reference);
    const auto info = subspace::SubspaceDeformer(space, constraints, backend(), settings).solve(result);
    EXPECT_EQ(info.status, referenceInfo.status);
    EXPECT_EQ(info.iterations, referenceInfo.iterations);
    EXPECT_LT(relativeDifference(result, reference), kAgreement);
    EXPECT_GT((reference - dome.vertices).cwiseAbs().maxCoeff(), 0.1 * lift) << "the handle moved the mesh";
  }
}

}  // namespace
}  // namespace plano::test
