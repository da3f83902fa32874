// The device's subspace ASAP/ARAP iterations (vk::ReducedArapKernels) against the host
// kernels (subspace/SubspaceDeformation.cpp): every iterate, the energies, the stopping
// iteration (inside a block of device iterations too) and the error on non-finite input.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "compute/ReducedArap.h"
#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"
#include "compute/vulkan/VulkanReducedArap.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "subspace/LinearSpace.h"
#include "subspace/SubspaceDeformation.h"
#include "subspace/SubspaceTopology.h"

namespace plano::test {
namespace {

using VulkanReducedArap = VulkanTest;

/// A vertical-space dome with 28 free dimensions once its first ring is fixed and one
/// vertex is pulled up (the command-line test's case).
struct DomeCase {
  DomeCase()
      : dome(generate::hexagonalDome(2)),
        space(subspace::buildLinearSpace(dome, subspace::uniformAssignment(subspace::SpaceKind::Vertical,
                                                                           dome.faceCount()))) {
    for (Index v = 0; v < 10; ++v) constraints.fixed.push_back(v);
    constraints.handles.push_back({40, Eigen::Vector3d(0.0, 0.0, 1.2)});
  }
  PolygonMesh dome;
  subspace::LinearSpace space;
  PositionalConstraints constraints;
};

struct DeformationRun {
  subspace::SubspaceDeformationInfo info;
  Positions result;
  std::vector<Positions> iterates;
};

DeformationRun deform(compute::Backend& backend, const DomeCase& c, const subspace::SubspaceDeformationSettings& settings) {
  DeformationRun run;
  run.result = c.dome.vertices;
  subspace::SubspaceDeformer deformer(c.space, c.constraints, backend, settings);
  run.info = deformer.solve(run.result, [&](Index, const Positions& X) { run.iterates.push_back(X); });
  return run;
}

double maxDistance(const Positions& a, const Positions& b) { return (a - b).rowwise().norm().maxCoeff(); }

TEST_F(VulkanReducedArap, TheBackendRunsTheIterationsOnTheDevice) {
  compute::ReducedArapProblem problem;
  problem.faces.addFace({0, 1, 2, 3});
  problem.source.resize(4, 3);
  problem.source << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  problem.basis.resize(12, 12);
  problem.basis.setIdentity();
  problem.gain = Eigen::MatrixXd::Identity(12, 12);
  problem.offset = Eigen::VectorXd::Zero(12);
  problem.constraints = compute::SparseMatrix(0, 12);
  problem.asap = true;
  bool built = false;
  auto kernels = backend().createReducedArapKernels([&] {
    built = true;
    return problem;
  });
  ASSERT_TRUE(kernels);
  EXPECT_TRUE(built);
  EXPECT_NE(dynamic_cast<vk::ReducedArapKernels*>(kernels.get()), nullptr);

  // With the identity as global step, x = the targets: a scaled, rotated, moved copy of
  // the rest face is recognized exactly (energy 0) and comes back centred.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Positions X(4, 3);
  for (Index v = 0; v < 4; ++v) X.row(v) = (2.0 * R * problem.source.row(v).transpose()).transpose() + Eigen::RowVector3d(5, -1, 2);
  kernels->start(X);
  const std::vector<compute::ReducedArapMeasures> measures = kernels->iterate(2);
  ASSERT_EQ(measures.size(), 2u);
  EXPECT_NEAR(measures[0].energy, 0.0, 1e-20);
  EXPECT_EQ(measures[0].constraintNorm, 0.0);
  Positions before, after;
  kernels->positions(0, before);
  kernels->positions(2, after);
  EXPECT_LT(maxDistance(before, X), 1e-15);
  const Eigen::RowVector3d centre = problem.source.colwise().mean();
  for (Index v = 0; v < 4; ++v) {
    const Eigen::RowVector3d expected = (2.0 * R * (problem.source.row(v) - centre).transpose()).transpose();
    EXPECT_LT((after.row(v) - expected).norm(), 1e-13) << "vertex " << v;
  }
  EXPECT_NEAR(measures[1].positionsNorm, after.norm(), 1e-13);
}

TEST_F(VulkanReducedArap, EveryIterateMatchesTheHostKernels) {
  const DomeCase dome;
  compute::CpuBackend cpu;
  const double diagonal = boundingBoxDiagonal(dome.dome.vertices);
  for (const subspace::DeformationEnergy energy : {subspace::DeformationEnergy::Asap, subspace::DeformationEnergy::Arap}) {
    SCOPED_TRACE(energy == subspace::DeformationEnergy::Asap ? "asap" : "arap");
    subspace::SubspaceDeformationSettings settings;
    settings.energy = energy;
    settings.maxIterations = vk::ReducedArapKernels::kBlock + 3;  // a full block and a partial one
    settings.tolerance = 0.0;                                        // run them all
    const DeformationRun host = deform(cpu, dome, settings);
    const DeformationRun device = deform(backend(), dome, settings);
    EXPECT_EQ(device.info.status, host.info.status);
    ASSERT_EQ(host.info.iterations, settings.maxIterations);
    ASSERT_EQ(device.info.iterations, host.info.iterations);
    ASSERT_EQ(device.iterates.size(), host.iterates.size());
    for (std::size_t k = 0; k < host.iterates.size(); ++k) {
      EXPECT_LT(maxDistance(device.iterates[k], host.iterates[k]), 1e-10 * diagonal) << "iterate " << k;
    }
    EXPECT_LT(maxDistance(device.result, host.result), 1e-10 * diagonal);
    EXPECT_NEAR(device.info.energy, host.info.energy, 1e-9 * host.info.energy);
    EXPECT_NEAR(device.info.maxSubspaceResidual, host.info.maxSubspaceResidual, 1e-12);
    EXPECT_NEAR(device.info.maxHandleDistance, host.info.maxHandleDistance, 1e-10 * diagonal);
  }
}

TEST_F(VulkanReducedArap, StopsAtTheHostIterateInsideABlock) {
  const DomeCase dome;
  compute::CpuBackend cpu;
  const subspace::SubspaceDeformationSettings settings;
  const DeformationRun host = deform(cpu, dome, settings);
  const DeformationRun device = deform(backend(), dome, settings);
  ASSERT_GT(subspace::SubspaceDeformer(dome.space, dome.constraints, cpu).freeDimension(), 0);
  ASSERT_EQ(host.info.status, subspace::DeformationStatus::Converged);
  EXPECT_GT(host.info.iterations, 2);
  ASSERT_NE(host.info.iterations % vk::ReducedArapKernels::kBlock, 0) << "the stop should fall inside a block";
  EXPECT_EQ(device.info.status, host.info.status);
  EXPECT_EQ(device.info.iterations, host.info.iterations);
  EXPECT_LT(maxDistance(device.result, host.result), 1e-10 * boundingBoxDiagonal(dome.dome.vertices));
  EXPECT_NEAR(device.info.energy, host.info.energy, 1e-9 * host.info.energy);
}

TEST_F(VulkanReducedArap, NonFiniteStartIsANumericalError) {
  const DomeCase dome;
  subspace::SubspaceDeformer deformer(dome.space, dome.constraints, backend());
  Positions X = dome.dome.vertices;
  X(3, 1) = std::numeric_limits<double>::quiet_NaN();
  try {
    deformer.solve(X);
    ADD_FAILURE() << "a NaN start was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Numerical);
    EXPECT_NE(std::string(e.what()).find("non-finite positions at iteration 0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace plano::test
