// Whole algorithms on the Vulkan backend against the CPU reference: the same mesh to
// 1e-6 of the bounding-box diagonal and the same iteration counts. The kernels agree to
// 1e-10 (their own tests); these check that nothing in an algorithm depends on which
// backend runs it (solver tolerances, iterative vs direct solves, warm starts).
#include <gtest/gtest.h>

#include <cstdlib>
#include <vector>

#include "compute/VulkanFixture.h"
#include "compute/cpu/CpuBackend.h"
#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "projective/Deformation.h"
#include "projective/MultiresDeformation.h"
#include "projective/PqSubdivision.h"
#include "subspace/LinearSpace.h"
#include "subspace/SubspaceDeformation.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

/// The agreement the project promises between backends, relative to the bounding-box diagonal.
constexpr double kAgreement = 1e-6;

double relativeDifference(const Positions& a, const Positions& b) {
  EXPECT_EQ(a.rows(), b.rows());
  if (a.rows() != b.rows()) return INFINITY;
  return (a - b).rowwise().norm().maxCoeff() / boundingBoxDiagonal(b);
}

/// An n x n translational grid's first column of vertices fixed, its far corner lifted.
PositionalConstraints fixedRowAndLiftedCorner(const PolygonMesh& grid, Index n) {
  PositionalConstraints constraints;
  for (Index i = 0; i <= n; ++i) constraints.fixed.push_back(i * (n + 1));
  const Index corner = n * (n + 1) + n;
  constraints.handles.push_back({corner, grid.vertices.row(corner).transpose() + Eigen::Vector3d(0.1, 0.1, 0.3)});
  return constraints;
}

/// Each iteration's largest copy (its largest transfers, reset per iteration) below half the
/// smallest mesh-sized array, the positions (24 B a vertex): a check's scalars or flags (the
/// largest, 288 B, the ADMM's measures of three columns).
void expectNoMeshSizedCopies(const std::vector<vk::TransferCounts>& iterations, const PolygonMesh& mesh) {
  const auto positionBytes = static_cast<std::uint64_t>(mesh.vertices.size()) * sizeof(double);
  for (const vk::TransferCounts& counts : iterations) {
    EXPECT_GT(counts.largestDownload, 0u);
    EXPECT_LT(counts.largestDownload, positionBytes / 2) << "a mesh-sized array came back";
    EXPECT_LT(counts.largestUpload, positionBytes / 2) << "a mesh-sized array went up";
  }
}

/// An n x n translational surface subdivided `levels` times on the CPU, its finest row
/// y = 0 fixed and its far corner lifted by `lift`.
struct MultiresCase {
  projective::PqSubdivisionResult hierarchy;
  PositionalConstraints constraints;
};

MultiresCase liftedCornerHierarchy(Index n, int levels, double lift) {
  compute::CpuBackend cpu;
  projective::PqSubdivisionSettings subdivision;
  subdivision.levels = levels;
  subdivision.planarityTolerance = 0.5;
  MultiresCase c{projective::subdividePlanarQuads(cpu, generate::translationalSurface(n, n), subdivision), {}};
  const Positions& finest = c.hierarchy.positions.back();
  const double yMin = finest.col(1).minCoeff();
  for (Index v = 0; v < finest.rows(); ++v) {
    if (finest(v, 1) < yMin + 1e-9) c.constraints.fixed.push_back(v);
  }
  Index corner = 0;
  (finest.col(0) + finest.col(1)).maxCoeff(&corner);
  c.constraints.handles.push_back({corner, finest.row(corner).transpose() + Eigen::Vector3d(0.0, 0.0, lift)});
  return c;
}

using WholeAlgorithmAgreement = VulkanTest;

TEST_F(WholeAlgorithmAgreement, SingleLevelDeformationGivesTheCpuMeshWithTheSameIterations) {
  const PolygonMesh grid = generate::translationalSurface(4, 4);
  const PositionalConstraints constraints = fixedRowAndLiftedCorner(grid, 4);
  compute::CpuBackend cpu;
  const projective::DeformationResult reference = projective::deform(cpu, grid, constraints);
  const projective::DeformationResult result = projective::deform(backend(), grid, constraints);
  ASSERT_EQ(reference.info.status, projective::DeformationStatus::Converged);
  EXPECT_EQ(result.info.status, reference.info.status);
  EXPECT_EQ(result.info.iterations, reference.info.iterations);
  EXPECT_LT(relativeDifference(result.mesh.vertices, reference.mesh.vertices), kAgreement);
  EXPECT_LT(result.info.planarity.max, 1e-6);
}

TEST_F(WholeAlgorithmAgreement, ASteadyDeformationIterationCopiesNoMeshSizedArray) {
  // After the first iteration (which uploads the solvers' matrices and the topology), the
  // rigid loop keeps its ideal maps, the global step's solution and the positions on the
  // device: each copy is a check's scalars or packed flags, far below the smallest mesh-
  // sized array (the positions, 24 B a vertex; the solution 96 B a face).
  const PolygonMesh grid = generate::translationalSurface(6, 6);
  const PositionalConstraints constraints = fixedRowAndLiftedCorner(grid, 6);
  projective::DeformationSettings settings;
  settings.maxIterations = 4;
  settings.maxProjectionIterations = 0;
  std::vector<vk::TransferCounts> steady;
  const auto result = projective::deform(backend(), grid, constraints, settings, [&](const projective::DeformationIteration& it) {
    if (it.iteration > 1) steady.push_back(context().transfers());
    context().resetLargestTransfers();
  });
  ASSERT_EQ(steady.size(), 3u);
  expectNoMeshSizedCopies(steady, grid);
  // The mesh is the CPU's, and the final positions came back.
  compute::CpuBackend cpu;
  const auto reference = projective::deform(cpu, grid, constraints, settings);
  EXPECT_LT(relativeDifference(result.mesh.vertices, reference.mesh.vertices), kAgreement);
  EXPECT_GT((result.mesh.vertices - grid.vertices).cwiseAbs().maxCoeff(), 0.05);
}

TEST_F(WholeAlgorithmAgreement, AProjectionPhaseGivesTheCpuMeshAndCopiesNoMeshSizedArray) {
  // The rigid phase stopped early leaves the faces bent: projective fits of the current
  // faces, projected with the same constraints, until they are planar. Those iterations
  // keep the fits, their induced scales (C's values), the solution and the positions on
  // the device: each copy is a check's scalars or flags.
  const PolygonMesh grid = generate::translationalSurface(6, 6);
  const PositionalConstraints constraints = fixedRowAndLiftedCorner(grid, 6);
  projective::DeformationSettings settings;
  settings.maxIterations = 2;
  settings.maxProjectionIterations = 4;
  settings.global.epsilonStart = projective::EpsilonStart::Relaxed;  // the paper's schedule: eps > 0 bends faces
  // Percent: below what the rigid phase leaves (0.16) and where the projections level off
  // (7.2e-5 after the second, on both backends): every projection iteration runs.
  settings.planarityTolerance = 1e-6;
  std::vector<vk::TransferCounts> projection;
  int projectionIterations = 0;
  const auto result = projective::deform(backend(), grid, constraints, settings, [&](const projective::DeformationIteration& it) {
    if (it.phase == projective::DeformationPhase::Projection && ++projectionIterations > 1) {
      projection.push_back(context().transfers());
    }
    context().resetLargestTransfers();
  });
  compute::CpuBackend cpu;
  const auto reference = projective::deform(cpu, grid, constraints, settings);
  int referenceProjections = 0;
  for (const auto& it : reference.info.history) referenceProjections += it.phase == projective::DeformationPhase::Projection;
  ASSERT_EQ(referenceProjections, 4) << "the case must exercise the projection phase";
  EXPECT_EQ(projectionIterations, referenceProjections);
  ASSERT_EQ(projection.size(), 3u);
  EXPECT_EQ(result.info.status, reference.info.status);
  EXPECT_LT(relativeDifference(result.mesh.vertices, reference.mesh.vertices), kAgreement);
  expectNoMeshSizedCopies(projection, grid);
}

TEST_F(WholeAlgorithmAgreement, CubeSubdivisionGivesTheCpuMeshWithTheSameIterations) {
  // Two whole levels: 2 + 2 local/global iterations, the second level's with stiff attempts
  // at eps down to 4e-7 (ADMM iterations per step 350 / 450 / 780 / 1 240 on both backends,
  // meshes 1.2e-11 of the diagonal apart; ~30 s on lavapipe since the subdivision's looser
  // dual tolerance, 65 s before it, 9 min before the stalled attempts stopped).
  projective::PqSubdivisionSettings settings;
  settings.levels = 2;
  compute::CpuBackend cpu;
  const projective::PqSubdivisionResult reference = projective::subdividePlanarQuads(cpu, generate::cube(), settings);
  // A level's later iterations keep the fits, their scales, the solution and the positions
  // on the device (its first uploads the level's matrices and topology).
  std::vector<std::vector<vk::TransferCounts>> steady(static_cast<std::size_t>(settings.levels));
  const projective::PqSubdivisionResult result = projective::subdividePlanarQuads(
      backend(), generate::cube(), settings, [&](int level, int iteration, const projective::PqIteration&) {
        if (iteration > 1) steady[static_cast<std::size_t>(level - 1)].push_back(context().transfers());
        context().resetLargestTransfers();
      });

  EXPECT_EQ(result.info.status, reference.info.status);
  EXPECT_EQ(result.info.totalIterations, reference.info.totalIterations);
  ASSERT_EQ(result.info.levels.size(), reference.info.levels.size());
  for (std::size_t l = 0; l < reference.info.levels.size(); ++l) {
    const auto& iterations = result.info.levels[l].iterations;
    const auto& expected = reference.info.levels[l].iterations;
    ASSERT_EQ(iterations.size(), expected.size()) << "level " << l + 1;
    for (std::size_t i = 0; i < expected.size(); ++i) {
      EXPECT_NEAR(iterations[i].epsilon, expected[i].epsilon, 1e-6 * expected[i].epsilon)
          << "level " << l + 1 << ", iteration " << i + 1;
    }
  }
  ASSERT_EQ(result.positions.size(), reference.positions.size());
  for (std::size_t l = 1; l < reference.positions.size(); ++l) {
    EXPECT_LT(relativeDifference(result.positions[l], reference.positions[l]), kAgreement) << "level " << l;
  }
  for (const auto& level : result.info.levels) {
    EXPECT_LT(level.planarity.max, level.linearMaxPlanarity) << "the iterations planarized the linear scheme's faces";
  }
  for (int l = 1; l <= settings.levels; ++l) {
    const auto& copies = steady[static_cast<std::size_t>(l - 1)];
    ASSERT_FALSE(copies.empty()) << "level " << l << " must have a steady iteration";
    expectNoMeshSizedCopies(copies, PolygonMesh{result.positions[static_cast<std::size_t>(l)], result.hierarchy.faces(l)});
  }
}

TEST_F(WholeAlgorithmAgreement, MultiresDeformationGivesTheCpuMeshWithTheSameIterations) {
  // A 3 x 3 translational surface subdivided twice (144 quads), its row y = 0 fixed and
  // a far corner lifted; the deformation runs on a coarse level and is prolongated.
  compute::CpuBackend cpu;
  const auto [hierarchy, constraints] = liftedCornerHierarchy(3, 2, 0.2);

  const projective::MultiresResult reference =
      projective::multiresDeform(cpu, hierarchy.hierarchy, hierarchy.positions, constraints);
  const projective::MultiresResult result =
      projective::multiresDeform(backend(), hierarchy.hierarchy, hierarchy.positions, constraints);
  ASSERT_EQ(reference.info.status, projective::MultiresStatus::Converged);
  EXPECT_EQ(result.info.status, reference.info.status);
  EXPECT_EQ(result.info.level, reference.info.level);
  EXPECT_EQ(result.info.coarseIterations, reference.info.coarseIterations);
  EXPECT_EQ(result.info.projectionIterations, reference.info.projectionIterations);
  EXPECT_LT(relativeDifference(result.positions, reference.positions), kAgreement);
}

TEST_F(WholeAlgorithmAgreement, MultiresProjectionIterationsGiveTheCpuMeshWithTheSameIterations) {
  // The paper's eps schedule from its relaxed start leaves the prolonged fine faces bent:
  // projection iterations (projective fits of the fine faces, projected with the fine
  // constraints) run on the fine level, on the device with their fits, scales, solution
  // and positions kept there.
  compute::CpuBackend cpu;
  const auto [hierarchy, constraints] = liftedCornerHierarchy(3, 1, 0.3);
  projective::MultiresSettings settings;
  settings.level = 0;
  settings.global.epsilonStart = projective::EpsilonStart::Relaxed;
  settings.planarityTolerance = 1e-6;  // percent: below what the relaxed fine step leaves
  settings.maxProjectionIterations = 3;

  const projective::MultiresResult reference =
      projective::multiresDeform(cpu, hierarchy.hierarchy, hierarchy.positions, constraints, settings);
  const projective::MultiresResult result =
      projective::multiresDeform(backend(), hierarchy.hierarchy, hierarchy.positions, constraints, settings);
  ASSERT_GT(reference.info.projectionIterations, 0) << "the case must exercise the projection iterations";
  EXPECT_EQ(result.info.projectionIterations, reference.info.projectionIterations);
  EXPECT_EQ(result.info.coarseIterations, reference.info.coarseIterations);
  EXPECT_EQ(result.info.status, reference.info.status);
  EXPECT_LT(relativeDifference(result.positions, reference.positions), kAgreement);
}

TEST_F(WholeAlgorithmAgreement, ASteadyMultiresCoarseIterationCopiesNoMeshSizedArray) {
  // The coarse loop keeps its normalized positions, ideal maps and solution on the device;
  // the last solution's maps come back once, for the prolongation. A 6 x 6 base (49
  // vertices: its positions, 1176 B, are well above a check's 288 B) subdivided once.
  compute::CpuBackend cpu;
  const auto [hierarchy, constraints] = liftedCornerHierarchy(6, 1, 0.3);
  projective::MultiresSettings settings;
  settings.level = 0;
  settings.maxCoarseIterations = 3;

  std::vector<vk::TransferCounts> steady;
  const projective::MultiresResult result = projective::multiresDeform(
      backend(), hierarchy.hierarchy, hierarchy.positions, constraints, settings,
      [&](const projective::MultiresIteration& it) {
        if (it.phase == projective::MultiresPhase::Coarse && it.iteration > 1) steady.push_back(context().transfers());
        context().resetLargestTransfers();
      });
  const projective::MultiresResult reference =
      projective::multiresDeform(cpu, hierarchy.hierarchy, hierarchy.positions, constraints, settings);
  ASSERT_EQ(result.info.coarseIterations, 3) << "the case must run every coarse iteration";
  EXPECT_EQ(reference.info.coarseIterations, result.info.coarseIterations);
  EXPECT_LT(relativeDifference(result.positions, reference.positions), kAgreement);
  ASSERT_EQ(steady.size(), 2u);
  expectNoMeshSizedCopies(steady, PolygonMesh{hierarchy.positions.front(), hierarchy.hierarchy.faces(0)});
  // Per iteration, the report's counts: a few kB of scalars whatever the mesh.
  ASSERT_EQ(result.info.coarseTransfers.size(), 3u);
  for (std::size_t i = 1; i < result.info.coarseTransfers.size(); ++i) {
    ASSERT_TRUE(result.info.coarseTransfers[i].has_value());
    EXPECT_GT(result.info.coarseTransfers[i]->copies, 0u);
  }
}

TEST_F(WholeAlgorithmAgreement, SubspaceDeformationGivesTheCpuMeshWithTheSameIterations) {
  // A vertical-space dome, its first ring fixed and one vertex pulled up: 28 free
  // dimensions, ~25 iterations to the default tolerance (more than one device block).
  const PolygonMesh dome = generate::hexagonalDome(2);
  const subspace::LinearSpace space = subspace::buildLinearSpace(
      dome, subspace::uniformAssignment(subspace::SpaceKind::Vertical, dome.faceCount()));
  PositionalConstraints constraints;
  for (Index v = 0; v < 10; ++v) constraints.fixed.push_back(v);
  constraints.handles.push_back({40, Eigen::Vector3d(0.0, 0.0, 1.2)});

  for (const subspace::DeformationEnergy energy : {subspace::DeformationEnergy::Asap, subspace::DeformationEnergy::Arap}) {
    subspace::SubspaceDeformationSettings settings;
    settings.energy = energy;
    compute::CpuBackend cpu;
    Positions reference = dome.vertices, result = dome.vertices;
    const auto referenceInfo = subspace::SubspaceDeformer(space, constraints, cpu, settings).solve(reference);
    const auto info = subspace::SubspaceDeformer(space, constraints, backend(), settings).solve(result);
    EXPECT_EQ(referenceInfo.status, subspace::DeformationStatus::Converged);
    EXPECT_GT(referenceInfo.iterations, 8);
    EXPECT_EQ(info.status, referenceInfo.status);
    EXPECT_EQ(info.iterations, referenceInfo.iterations);
    EXPECT_LT(relativeDifference(result, reference), kAgreement);
    EXPECT_GT((reference - dome.vertices).cwiseAbs().maxCoeff(), 0.1) << "the handle moved the mesh";
  }
}

TEST_F(WholeAlgorithmAgreement, ASubspaceDeformationOfARealGridshellGivesTheCpuMeshWithTheSameIterations) {
  // Gitter (1 216 quads, planar to 5e-3 %) in its affine space (378 dimensions): the
  // vertices on the ground fixed, the highest one pulled up by 5 % of the height. Measured:
  // 351 ASAP and 226 ARAP iterations to the default tolerance on both backends.
  PLANO_REQUIRE_SHARED_MESH(path, "gitter.off");
  const PolygonMesh gitter = readMesh(path);
  const subspace::LinearSpace space = subspace::buildLinearSpace(
      gitter, subspace::uniformAssignment(subspace::SpaceKind::Affine, gitter.faceCount()));
  PositionalConstraints constraints;
  const double ground = gitter.vertices.col(2).minCoeff(), height = gitter.vertices.col(2).maxCoeff() - ground;
  for (Index v = 0; v < gitter.vertexCount(); ++v) {
    if (gitter.vertices(v, 2) < ground + 0.02 * height) constraints.fixed.push_back(v);
  }
  Index top = 0;
  gitter.vertices.col(2).maxCoeff(&top);
  constraints.handles.push_back({top, gitter.vertices.row(top).transpose() + Eigen::Vector3d(0.0, 0.0, 0.05 * height)});
  ASSERT_GT(constraints.fixed.size(), 10u);

  for (const subspace::DeformationEnergy energy : {subspace::DeformationEnergy::Asap, subspace::DeformationEnergy::Arap}) {
    subspace::SubspaceDeformationSettings settings;
    settings.energy = energy;
    settings.maxIterations = 1000;
    compute::CpuBackend cpu;
    Positions reference = gitter.vertices, result = gitter.vertices;
    const auto referenceInfo = subspace::SubspaceDeformer(space, constraints, cpu, settings).solve(reference);
    const auto info = subspace::SubspaceDeformer(space, constraints, backend(), settings).solve(result);
    EXPECT_EQ(referenceInfo.status, subspace::DeformationStatus::Converged);
    EXPECT_EQ(info.status, referenceInfo.status);
    EXPECT_EQ(info.iterations, referenceInfo.iterations);
    EXPECT_LT(relativeDifference(result, reference), kAgreement);
    EXPECT_GT((reference - gitter.vertices).cwiseAbs().maxCoeff(), 0.01 * height) << "the handle moved the mesh";
  }
}

TEST_F(WholeAlgorithmAgreement, AProjectiveDeformationOfARealMeshGivesTheCpuMeshWithTheSameIterations) {
  // The double torus (34 planar quads, genus 2): four vertices fixed, another one moved by
  // 1 % of the bounding-box diagonal. Measured: 7 iterations on both backends, each an
  // exact step (solved directly on the CPU, by the polish's method of multipliers alone on
  // the device).
  PLANO_REQUIRE_SHARED_MESH(path, "double_torus_quads.off");
  const PolygonMesh torus = readMesh(path);
  PositionalConstraints constraints;
  constraints.fixed = {0, 1, 2, 3};
  const Index moved = torus.vertexCount() - 1;
  constraints.handles.push_back(
      {moved, torus.vertices.row(moved).transpose() + Eigen::Vector3d(0.0, 0.0, 0.01 * boundingBoxDiagonal(torus.vertices))});
  compute::CpuBackend cpu;
  const projective::DeformationResult reference = projective::deform(cpu, torus, constraints);
  const projective::DeformationResult result = projective::deform(backend(), torus, constraints);
  ASSERT_EQ(reference.info.status, projective::DeformationStatus::Converged) << reference.info.message;
  EXPECT_EQ(result.info.status, reference.info.status) << result.info.message;
  EXPECT_EQ(result.info.iterations, reference.info.iterations);
  EXPECT_LT(relativeDifference(result.mesh.vertices, reference.mesh.vertices), kAgreement);
  EXPECT_LT(result.info.planarity.max, 1e-6);
}

}  // namespace
}  // namespace plano::test
