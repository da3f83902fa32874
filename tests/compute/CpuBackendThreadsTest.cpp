// The CPU backend's batched per-face kernels split the faces over threads (core/
// ParallelFor.h): each face's result must not depend on how many there are.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "compute/cpu/CpuBackend.h"
#include "core/ParallelFor.h"
#include "mesh/Generators.h"
#include "projective/ProjectiveTestHelpers.h"

namespace plano::test {
namespace {

struct KernelResults {
  std::vector<double> planarity;
  compute::ProjectiveFits fits;
  compute::IdealMaps ideal;
  std::vector<Eigen::Matrix3d> rotations;
  std::vector<Eigen::Vector3d> singularValues;
};

KernelResults runKernels(int threads, const PolygonMesh& moved, const Positions& source,
                         const std::vector<Eigen::Matrix3d>& matrices) {
  setCpuThreads(threads);
  compute::CpuBackend cpu;
  KernelResults out;
  out.planarity.resize(static_cast<std::size_t>(moved.faceCount()));
  cpu.facePlanarity(moved, out.planarity);
  cpu.fitProjectiveMaps(moved.faces, source, moved.vertices, out.fits);
  cpu.closestIdealMaps(moved.faces, source, out.fits.maps, &moved.vertices, true, out.ideal);
  out.rotations.resize(matrices.size());
  out.singularValues.resize(matrices.size());
  cpu.closestRotations(matrices, out.rotations, out.singularValues);
  setCpuThreads(0);
  return out;
}

TEST(CpuBackendThreads, EveryBatchedKernelGivesTheSameResultsBitForBitOnOneAndSeveralThreads) {
  // 40 960 quads: more than two threads' minimum share of every kernel, planarity's too.
  PolygonMesh moved = generate::translationalSurface(256, 160);
  const Positions source = moved.vertices;
  moved.vertices = rotatedScaledAndPerturbed(source, 1.3, 0.01, 7);
  std::mt19937 random(3);
  std::normal_distribution<double> normal;
  std::vector<Eigen::Matrix3d> matrices(5000);
  for (Eigen::Matrix3d& m : matrices) m = Eigen::Matrix3d::NullaryExpr([&] { return normal(random); });

  const KernelResults one = runKernels(1, moved, source, matrices);
  for (int threads : {2, 3}) {
    SCOPED_TRACE(threads);
    const KernelResults several = runKernels(threads, moved, source, matrices);
    EXPECT_EQ(several.planarity, one.planarity);
    EXPECT_EQ(several.fits.maps, one.fits.maps);
    EXPECT_EQ(several.fits.reciprocalScales, one.fits.reciprocalScales);
    EXPECT_EQ(several.fits.residuals, one.fits.residuals);
    EXPECT_EQ(several.fits.ranks, one.fits.ranks);
    EXPECT_EQ(several.ideal.maps, one.ideal.maps);
    EXPECT_EQ(several.ideal.methods, one.ideal.methods);
    EXPECT_EQ(several.rotations, one.rotations);
    EXPECT_EQ(several.singularValues, one.singularValues);
  }
  EXPECT_GT(*std::max_element(one.planarity.begin(), one.planarity.end()), 0.0) << "the moved faces are not planar";
}

}  // namespace
}  // namespace plano::test
