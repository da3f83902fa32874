// Creating an initial mesh from a topology on Vulkan (linear-spaces paper, §4): the Tutte
// embedding's interior solve (the backend's PCG) and the lifting's reduced operator give the
// CPU's (CHOLMOD's, Eigen's) meshes.
#include <gtest/gtest.h>

#include "compute/VulkanFixture.h"
#include "mesh/Generators.h"
#include "subspace/AffineLifting.h"
#include "subspace/TutteEmbedding.h"

namespace plano::test {
namespace {

using VulkanEmbedding = VulkanTest;

double largestDistance(const Positions& a, const Positions& b) { return (a - b).rowwise().norm().maxCoeff(); }

TEST_F(VulkanEmbedding, TheTutteEmbeddingIsTheCpus) {
  // 7 x 5 quads: 24 boundary and 24 interior vertices; 60 x 60: 3 481 interior ones, where
  // the Laplacian's condition number makes the iterative solve's tolerance matter.
  for (const auto& [nu, nv] : {std::pair{7, 5}, std::pair{60, 60}}) {
    const PolygonMesh grid = generate::translationalSurface(nu, nv);
    subspace::TutteInfo device, host;
    const Positions X = subspace::tutteEmbedding(backend(), grid.faces, grid.vertexCount(), {}, &device);
    const Positions Y = subspace::tutteEmbedding(grid.faces, grid.vertexCount(), {}, &host);
    EXPECT_EQ(device.interiorVertices, host.interiorVertices);
    EXPECT_EQ(device.flippedFaces, 0);
    EXPECT_LT(largestDistance(X, Y), 1e-10) << nu << " x " << nv;  // the boundary circle has radius 1
  }
}

TEST_F(VulkanEmbedding, LiftingsAreTheCpus) {
  const PolygonMesh grid = generate::translationalSurface(7, 5);
  const PolygonMesh flat{subspace::tutteEmbedding(grid.faces, grid.vertexCount()), grid.faces};
  for (subspace::LiftKind kind : {subspace::LiftKind::Eigenshape, subspace::LiftKind::Handle}) {
    subspace::LiftSettings settings;
    settings.kind = kind;
    subspace::LiftInfo device, host;
    const PolygonMesh a = subspace::liftWithAffineSpace(backend(), flat, settings, &device);
    const PolygonMesh b = subspace::liftWithAffineSpace(flat, settings, &host);
    EXPECT_EQ(device.liftings, host.liftings);
    EXPECT_LT(largestDistance(a.vertices, b.vertices), 1e-10 * boundingBoxDiagonal(b.vertices));
  }
}

}  // namespace
}  // namespace plano::test
