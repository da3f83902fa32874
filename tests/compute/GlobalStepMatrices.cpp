#include "compute/GlobalStepMatrices.h"

#include <Eigen/Geometry>
#include <string>

#include "compute/Admm.h"
#include "mesh/Generators.h"
#include "projective/GlobalStep.h"
#include "projective/ShapeSpace.h"
#include "support/CpuForwardingBackend.h"

namespace plano::test {
namespace {

/// Keeps the P and C of the first ADMM solver a global step creates.
class MatrixCapture : public CpuForwardingBackend {
 public:
  std::string name() const override { return "capture"; }
  std::unique_ptr<compute::AdmmSolver> createAdmmSolver(const compute::SparseMatrix& P, const compute::SparseMatrix& C,
                                                        const compute::AdmmSettings& settings) override {
    if (this->P.size() == 0) {
      this->P = P;
      this->C = C;
    }
    return Backend::createAdmmSolver(P, C, settings);
  }
  compute::SparseMatrix P, C;
};

}  // namespace

compute::SparseMatrix GlobalStepMatrices::K(double rho) const {
  compute::SparseMatrix I(P.rows(), P.rows());
  I.setIdentity();
  const compute::SparseMatrix CtC = C.transpose() * C;
  compute::SparseMatrix K = P + I * sigma + CtC * rho;
  K.makeCompressed();
  return K;
}

GlobalStepMatrices globalStepMatrices(Index side) {
  const PolygonMesh mesh = generate::translationalSurface(side, side);
  const projective::ShapeSpace space(mesh);
  std::vector<Index> fixed;
  for (Index i = 0; i <= side; ++i) fixed.push_back(i * (side + 1));
  Positions at(static_cast<Index>(fixed.size()), 3);
  for (std::size_t i = 0; i < fixed.size(); ++i) at.row(static_cast<Index>(i)) = mesh.vertices.row(fixed[i]);
  std::vector<Eigen::Matrix4d> targets(space.faceCount(), Eigen::Matrix4d::Identity());
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (Index f = 0; f < space.faceCount(); f += 2) targets[f].topLeftCorner<3, 3>() = R;
  projective::GlobalStepSettings settings;
  settings.epsilonStart = projective::EpsilonStart::ExactFirst;
  MatrixCapture capture;
  projective::GlobalStep global(capture, space, fixed, settings);
  projective::FaceMaps maps;
  global.solve(targets, at, maps);
  GlobalStepMatrices matrices;
  matrices.P = capture.P;
  matrices.C = capture.C;
  matrices.sigma = settings.qp.sigma;
  return matrices;
}

}  // namespace plano::test
