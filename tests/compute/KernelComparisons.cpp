#include "compute/KernelComparisons.h"

#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "compute/cpu/CpuBackend.h"

namespace plano::test {

double planarityDifference(compute::Backend& backend, const PolygonMesh& mesh) {
  std::vector<double> tested(mesh.faceCount()), cpu(mesh.faceCount());
  backend.facePlanarity(mesh, tested);
  compute::CpuBackend().facePlanarity(mesh, cpu);
  double worst = 0.0;
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    worst = std::max(worst, std::abs(tested[f] - cpu[f]) / std::max(std::abs(cpu[f]), 1.0));
  }
  return worst;
}

FitComparison compareFits(compute::Backend& backend, const FaceList& faces, const Positions& source,
                          const Positions& target) {
  compute::ProjectiveFits tested, cpu;
  backend.fitProjectiveMaps(faces, source, target, tested);
  compute::CpuBackend().fitProjectiveMaps(faces, source, target, cpu);
  FitComparison c;
  c.faces = faces.size();
  for (Index f = 0; f < faces.size(); ++f) {
    double face = 0.0;
    for (int e = 0; e < 16; ++e) {
      const double a = tested.maps[f].data()[e], b = cpu.maps[f].data()[e];
      face = std::max(face, std::abs(a - b) / std::max(1.0, std::abs(b)));
    }
    const Eigen::Vector4d singular = Eigen::JacobiSVD<Eigen::Matrix4d>(cpu.maps[f]).singularValues();
    const double condition = singular[0] / std::max(singular[3], 1e-300);
    c.maps = std::max(c.maps, face);
    c.conditionedMaps = std::max(c.conditionedMaps, face / std::max(1.0, condition / 1e3));
    c.largestCondition = std::max(c.largestCondition, condition);
    c.residuals = std::max(c.residuals, std::abs(tested.residuals[f] - cpu.residuals[f]));
    c.largestResidual = std::max(c.largestResidual, cpu.residuals[f]);
    if (tested.ranks[f] != cpu.ranks[f]) ++c.rankMismatches;
  }
  for (std::size_t i = 0; i < cpu.reciprocalScales.size(); ++i) {
    const double a = tested.reciprocalScales[i], b = cpu.reciprocalScales[i];
    c.scales = std::max(c.scales, std::abs(a - b) / std::max(1.0, std::abs(b)));
  }
  return c;
}

namespace {

void expectScalesResidualsAndRanksAgree(const FitComparison& c) {
  EXPECT_LT(c.scales, 1e-10);
  EXPECT_LT(c.residuals, 1e-10);
  EXPECT_EQ(c.rankMismatches, 0) << "of " << c.faces << " faces";
}

}  // namespace

void expectFitAgreement(const FitComparison& c) {
  EXPECT_LT(c.maps, 1e-10);
  expectScalesResidualsAndRanksAgree(c);
}

void expectConditionedFitAgreement(const FitComparison& c) {
  EXPECT_LT(c.conditionedMaps, 1e-10) << "largest condition number " << c.largestCondition;
  expectScalesResidualsAndRanksAgree(c);
}

RotationComparison compareRotations(compute::Backend& backend, const std::vector<Eigen::Matrix3d>& matrices) {
  const std::size_t n = matrices.size();
  std::vector<Eigen::Matrix3d> testedR(n), cpuR(n);
  std::vector<Eigen::Vector3d> testedS(n), cpuS(n);
  backend.closestRotations(matrices, testedR, testedS);
  compute::CpuBackend().closestRotations(matrices, cpuR, cpuS);
  RotationComparison c;
  for (std::size_t i = 0; i < n; ++i) {
    c.rotations = std::max(c.rotations, (testedR[i] - cpuR[i]).cwiseAbs().maxCoeff());
    c.singularValues =
        std::max(c.singularValues, (testedS[i] - cpuS[i]).cwiseAbs().maxCoeff() / std::max(cpuS[i][0], 1e-300));
    c.orthogonality = std::max(
        c.orthogonality, (testedR[i].transpose() * testedR[i] - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff());
    c.determinant = std::max(c.determinant, std::abs(testedR[i].determinant() - 1.0));
  }
  return c;
}

void expectRotationAgreement(const RotationComparison& c) {
  EXPECT_LT(c.rotations, 1e-10);
  EXPECT_LT(c.singularValues, 1e-10);
  EXPECT_LT(c.orthogonality, 1e-12);
  EXPECT_LT(c.determinant, 1e-12);
}

IdealComparison compareIdealMaps(compute::Backend& backend, const FaceList& faces, const Positions& source,
                                 const std::vector<Eigen::Matrix4d>& fitted, const Positions* target, bool similar) {
  compute::IdealMaps tested, cpu;
  backend.closestIdealMaps(faces, source, fitted, target, similar, tested);
  compute::CpuBackend().closestIdealMaps(faces, source, fitted, target, similar, cpu);
  IdealComparison c;
  for (Index f = 0; f < faces.size(); ++f) {
    for (int e = 0; e < 16; ++e) {
      const double a = tested.maps[f].data()[e], b = cpu.maps[f].data()[e];
      c.maps = std::max(c.maps, std::abs(a - b) / std::max(1.0, std::abs(b)));
    }
    if (tested.methods[f] != cpu.methods[f]) ++c.methodMismatches;
    if (cpu.methods[f] == compute::IdealMapMethod::CornerProcrustes) ++c.fallbacks;
    c.largestRotation = std::max(
        c.largestRotation, (cpu.maps[f].topLeftCorner<3, 3>() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff());
  }
  return c;
}

}  // namespace plano::test
