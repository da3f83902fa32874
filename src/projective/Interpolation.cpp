#include "projective/Interpolation.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <string>

#include "core/Error.h"
#include "projective/LocalStep.h"

namespace plano::projective {

MapFactors factorMap(const Eigen::Matrix4d& T) {
  MapFactors factors;
  factors.perspective = T.block<3, 1>(0, 3) / T(3, 3);
  factors.translation = T.block<1, 3>(3, 0) / T(3, 3);
  const Eigen::Matrix3d H = T.topLeftCorner<3, 3>() / T(3, 3) - factors.perspective * factors.translation;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d sigma = svd.singularValues();
  if (!(sigma[2] > 1e-12 * std::max(sigma[0], 1e-300)) || !H.allFinite()) {
    throwNumerical("map factorization: the affine part is singular");
  }
  if (H.determinant() < 0.0) throwNumerical("map factorization: the affine part reverses orientation");
  // H = U S V^T = (U S U^T)(U V^T) = Q R.
  factors.stretch = svd.matrixU() * sigma.asDiagonal() * svd.matrixU().transpose();
  factors.rotation = svd.matrixU() * svd.matrixV().transpose();
  return factors;
}

Eigen::Matrix4d interpolatedMap(const MapFactors& factors, double t) {
  const Eigen::AngleAxisd angleAxis(factors.rotation);
  const Eigen::Matrix3d rotationPower = Eigen::AngleAxisd(t * angleAxis.angle(), angleAxis.axis()).toRotationMatrix();
  const Eigen::Matrix3d H = (t * factors.stretch + (1.0 - t) * Eigen::Matrix3d::Identity()) * rotationPower;
  Eigen::Matrix4d projective = Eigen::Matrix4d::Identity();
  projective.block<3, 1>(0, 3) = t * factors.perspective;
  Eigen::Matrix4d affine = Eigen::Matrix4d::Identity();
  affine.topLeftCorner<3, 3>() = H;
  affine.block<1, 3>(3, 0) = t * factors.translation;
  return projective * affine;
}

namespace {

const PolygonMesh& checkedSameTopology(const PolygonMesh& a, const PolygonMesh& b) {
  if (a.vertexCount() != b.vertexCount()) {
    throwBadInput("interpolation: the meshes have " + std::to_string(a.vertexCount()) + " and " +
                  std::to_string(b.vertexCount()) + " vertices");
  }
  if (a.faceCount() != b.faceCount()) {
    throwBadInput("interpolation: the meshes have " + std::to_string(a.faceCount()) + " and " +
                  std::to_string(b.faceCount()) + " faces");
  }
  for (Index f = 0; f < a.faceCount(); ++f) {
    const auto fa = a.faces[f];
    const auto fb = b.faces[f];
    if (!std::equal(fa.begin(), fa.end(), fb.begin(), fb.end())) {
      throwBadInput("interpolation: face " + std::to_string(f) + " differs between the meshes");
    }
  }
  return a;
}

}  // namespace

Interpolation::Interpolation(compute::Backend& backend, const PolygonMesh& a, const PolygonMesh& b,
                             const InterpolationSettings& settings)
    : backend_(backend), space_(checkedSameTopology(a, b)), global_(backend, space_, {}, settings.global) {
  const LocalStepResult fit = fitFaceMaps(backend_, space_, b.vertices);
  factors_.resize(space_.faceCount());
  for (Index f = 0; f < space_.faceCount(); ++f) {
    try {
      factors_[f] = factorMap(fit.fits.maps[f]);
    } catch (const Error& e) {
      throwNumerical("interpolation: face " + std::to_string(f) + ": " + e.what());
    }
  }
}

PolygonMesh Interpolation::at(double t, GlobalStepInfo* info) {
  if (!std::isfinite(t)) throwUsage("interpolation: t must be finite");
  std::vector<Eigen::Matrix4d> targets(space_.faceCount());
  for (Index f = 0; f < space_.faceCount(); ++f) targets[f] = interpolatedMap(factors_[f], t);
  FaceMaps maps;
  const GlobalStepInfo stepInfo = global_.solve(targets, Positions(), maps);
  if (info) *info = stepInfo;
  PolygonMesh mesh;
  mesh.faces = space_.faces();
  mesh.vertices = space_.positions(maps.maps);
  return mesh;
}

}  // namespace plano::projective
