#include "projective/Deformation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano::projective {
namespace {

/// A generated polyhedral grid (n x n parallelograms) with the row v = 0 fixed and the
/// opposite corner moved by `offset`.
struct GridCase {
  PolygonMesh mesh;
  PositionalConstraints constraints;
};

GridCase gridCase(Index n, const Eigen::Vector3d& offset) {
  GridCase c;
  c.mesh = generate::translationalSurface(n, n);
  for (Index i = 0; i <= n; ++i) c.constraints.fixed.push_back(i * (n + 1));  // vertices (i, 0)
  const Index corner = n * (n + 1) + n;
  c.constraints.handles.push_back({corner, c.mesh.vertices.row(corner).transpose() + offset});
  return c;
}

void expectConstraintsHold(const GridCase& c, const Positions& result, double tolerance) {
  for (Index v : c.constraints.fixed) {
    EXPECT_LT((result.row(v) - c.mesh.vertices.row(v)).norm(), tolerance) << "fixed vertex " << v;
  }
  for (const Handle& h : c.constraints.handles) {
    EXPECT_LT((result.row(h.vertex).transpose() - h.position).norm(), tolerance) << "handle " << h.vertex;
  }
}

class DeformationTest : public ::testing::Test {
 protected:
  compute::CpuBackend backend;
};

TEST_F(DeformationTest, GridWithFixedRowAndMovedCornerConvergesAndStaysExactlyPlanar) {
  const GridCase c = gridCase(8, {0.1, 0.1, 0.3});
  const DeformationResult r = deform(backend, c.mesh, c.constraints);
  EXPECT_EQ(r.info.status, DeformationStatus::Converged);
  EXPECT_GT(r.info.iterations, 1);
  ASSERT_EQ(static_cast<int>(r.info.history.size()), r.info.iterations);
  // eps = 0 is reachable here (the affine shape space of a parallelogram grid holds
  // exact solutions): every global step is exact and every face stays planar. Its
  // all-equality QP is solved directly on the CPU, without ADMM iterations.
  for (const auto& it : r.info.history) {
    EXPECT_EQ(it.epsilon, 0.0) << "iteration " << it.iteration;
    EXPECT_LT(it.constraintResidual, 1e-9) << "iteration " << it.iteration;
    EXPECT_EQ(it.admmIterations, 0);
    ASSERT_EQ(it.attempts.size(), 1u);
    EXPECT_TRUE(it.attempts[0].direct);
  }
  EXPECT_LT(r.info.history.back().displacement, DeformationSettings{}.tolerance);
  EXPECT_LT(r.info.planarity.max, 1e-8);
  expectConstraintsHold(c, r.mesh.vertices, 1e-9);
  // The handle pulled the free part: the vertex next to it moved a lot.
  const Index nearHandle = c.constraints.handles[0].vertex - 1;
  EXPECT_GT((r.mesh.vertices.row(nearHandle) - c.mesh.vertices.row(nearHandle)).norm(), 0.1);
}

TEST_F(DeformationTest, PaperEpsilonScheduleEndsBelowTheTenthOfAPercent) {
  const GridCase c = gridCase(8, {0.1, 0.1, 0.3});
  DeformationSettings settings;
  settings.global.epsilonStart = EpsilonStart::Relaxed;
  const DeformationResult r = deform(backend, c.mesh, c.constraints, settings);
  EXPECT_EQ(r.info.status, DeformationStatus::Converged);
  EXPECT_LT(r.info.planarity.max, 0.1);
  bool relaxed = false;
  for (const auto& it : r.info.history) {
    relaxed = relaxed || it.epsilon > 0.0;
    EXPECT_LE(it.constraintResidual, it.epsilon + 1e-6) << "iteration " << it.iteration;
    EXPECT_LT(it.positionalResidual, 1e-9) << "iteration " << it.iteration;
  }
  EXPECT_TRUE(relaxed);
  expectConstraintsHold(c, r.mesh.vertices, 1e-9);
}

TEST_F(DeformationTest, SimilarEnergyConvergesAndReachesTheHandle) {
  const GridCase c = gridCase(6, {0.3, 0.2, 0.0});
  DeformationSettings settings;
  settings.energy = IdealMapKind::Similar;
  const DeformationResult r = deform(backend, c.mesh, c.constraints, settings);
  EXPECT_EQ(r.info.status, DeformationStatus::Converged);
  EXPECT_LT(r.info.planarity.max, 0.1);
  expectConstraintsHold(c, r.mesh.vertices, 1e-9);
}

TEST_F(DeformationTest, HandleAtItsRestPositionChangesNothing) {
  const GridCase c = gridCase(5, Eigen::Vector3d::Zero());
  const DeformationResult r = deform(backend, c.mesh, c.constraints);
  EXPECT_EQ(r.info.status, DeformationStatus::Converged);
  EXPECT_EQ(r.info.iterations, 1);
  EXPECT_LT(test::maxAbsDifference(r.mesh.vertices, c.mesh.vertices), 1e-12);
}

TEST_F(DeformationTest, IterationCapIsReportedNotThrown) {
  const GridCase c = gridCase(6, {0.1, 0.1, 0.3});
  DeformationSettings settings;
  settings.maxIterations = 2;
  const DeformationResult r = deform(backend, c.mesh, c.constraints, settings);
  EXPECT_EQ(r.info.status, DeformationStatus::MaxIterationsReached);
  EXPECT_EQ(r.info.iterations, 2);
}

TEST_F(DeformationTest, SolverIsReusableWithMovedHandles) {
  const GridCase c = gridCase(5, {0.0, 0.0, 0.2});
  Deformation deformation(backend, c.mesh, c.constraints);
  Positions positions = c.mesh.vertices;
  Positions handles(1, 3);
  handles.row(0) = c.constraints.handles[0].position.transpose();
  EXPECT_EQ(deformation.solve(handles, positions).status, DeformationStatus::Converged);
  handles(0, 2) += 0.1;  // drag further, warm-started from the last result
  const DeformationInfo info = deformation.solve(handles, positions);
  EXPECT_EQ(info.status, DeformationStatus::Converged);
  EXPECT_LT((positions.row(c.constraints.handles[0].vertex) - handles.row(0)).norm(), 1e-9);
}

TEST_F(DeformationTest, NonFiniteStartingPositionsAreABadInputErrorNamingTheVertex) {
  const GridCase c = gridCase(3, {0.0, 0.0, 0.2});
  Deformation deformation(backend, c.mesh, c.constraints);
  Positions handles(1, 3);
  handles.row(0) = c.constraints.handles[0].position.transpose();
  Positions positions = c.mesh.vertices;
  positions(5, 1) = std::nan("");
  try {
    deformation.solve(handles, positions);
    ADD_FAILURE() << "expected Error(BadInput)";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("vertex 5 "), std::string::npos) << e.what();
  }
}

TEST_F(DeformationTest, GitterMeshKeepsItsPlanarity) {
  PLANO_REQUIRE_SHARED_MESH(path, "gitter.off");
  const PolygonMesh mesh = readMesh(path);
  PositionalConstraints constraints;
  const double xmin = mesh.vertices.col(0).minCoeff();
  const double xmax = mesh.vertices.col(0).maxCoeff();
  Index far = 0;
  for (Index v = 0; v < mesh.vertexCount(); ++v) {
    if (mesh.vertices(v, 0) < xmin + 0.1 * (xmax - xmin)) constraints.fixed.push_back(v);
    if (mesh.vertices(v, 0) > mesh.vertices(far, 0)) far = v;
  }
  const double diagonal = boundingBoxDiagonal(mesh.vertices);
  constraints.handles.push_back({far, mesh.vertices.row(far).transpose() + Eigen::Vector3d(0, 0, 0.1 * diagonal)});
  DeformationSettings settings;
  settings.tolerance = 1e-3;
  const DeformationResult r = deform(backend, mesh, constraints, settings);
  EXPECT_EQ(r.info.status, DeformationStatus::Converged);
  EXPECT_LT(r.info.planarity.max, 0.1);
  EXPECT_LT(r.info.maxConstraintError, 1e-6 * diagonal);
}

}  // namespace
}  // namespace plano::projective
