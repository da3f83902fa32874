// The planarizers use only the Backend interface: they must give the CPU reference's
// result with any backend, including one whose SPD solver is iterative and cannot
// refactor (as a device PCG), and with the Vulkan backend where one is available.
#include <gtest/gtest.h>

#include <Eigen/IterativeLinearSolvers>

#include "compute/cpu/CpuBackend.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "planarize/Planarize.h"
#include "planarize/PlanarizeTestMeshes.h"
#include "support/CpuForwardingBackend.h"
#include "support/TestMeshes.h"

namespace plano::planarize {
namespace {

/// Conjugate gradients from the caller's warm start, no refactor: the shape of a device
/// PCG solver, on the CPU.
class ConjugateGradientSolver final : public compute::SpdSolver {
 public:
  explicit ConjugateGradientSolver(const compute::SparseMatrix& A) : matrix_(A) {
    cg_.setTolerance(1e-13);
    cg_.setMaxIterations(10 * static_cast<int>(A.rows()) + 100);
    cg_.compute(matrix_);
  }
  compute::LinearSolveInfo solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X) override {
    compute::LinearSolveInfo info;
    if (X.rows() != B.rows() || X.cols() != B.cols()) X.setZero(B.rows(), B.cols());
    for (Eigen::Index c = 0; c < B.cols(); ++c) {
      const Eigen::VectorXd x = cg_.solveWithGuess(B.col(c), X.col(c));
      X.col(c) = x;
      info.iterations = std::max(info.iterations, static_cast<int>(cg_.iterations()));
      info.relativeResidual = std::max(info.relativeResidual, cg_.error());
    }
    info.converged = cg_.info() == Eigen::Success;
    return info;
  }
  Eigen::Index size() const override { return matrix_.rows(); }

 private:
  Eigen::SparseMatrix<double> matrix_;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg_;
};

class IterativeSolverBackend final : public test::CpuForwardingBackend {
 public:
  std::string name() const override { return "cpu with conjugate gradients"; }
  std::unique_ptr<compute::SpdSolver> createSpdSolver(const compute::SparseMatrix& A,
                                                      const compute::LinearSolverSettings&) override {
    ++solversCreated;
    return std::make_unique<ConjugateGradientSolver>(A);
  }
  int solversCreated = 0;
};

void expectAgreement(const PolygonMesh& mesh, const Settings& settings, compute::Backend& other) {
  compute::CpuBackend cpu;
  Positions reference = mesh.vertices, result = mesh.vertices;
  const Info referenceInfo = planarize::planarize(mesh.faces, reference, settings, cpu);
  const Info info = planarize::planarize(mesh.faces, result, settings, other);
  EXPECT_EQ(info.status, referenceInfo.status) << toString(settings.method);
  EXPECT_EQ(info.iterations, referenceInfo.iterations) << toString(settings.method);
  EXPECT_LT(test::maxAbsDifference(result, reference), 1e-6) << toString(settings.method);
}

TEST(PlanarizeBackendAgreement, IterativeSolverWithoutRefactorGivesTheCpuResult) {
  const PolygonMesh mesh = test::mixedDegreeHyparPatch();
  for (const Method method : {Method::GaussNewton, Method::Guided, Method::Anderson, Method::ShapeUp}) {
    IterativeSolverBackend backend;
    Settings settings;
    settings.method = method;
    settings.tolerance = method == Method::GaussNewton || method == Method::Guided ? 0.1 : 2.0;
    settings.maxIterations = 300;
    expectAgreement(mesh, settings, backend);
    EXPECT_GT(backend.solversCreated, 0);
  }
}

TEST(PlanarizeBackendAgreement, VulkanBackendGivesTheCpuResult) {
  std::unique_ptr<compute::Backend> vulkan;
  try {
    vulkan = compute::createBackend(compute::BackendChoice::Vulkan);
  } catch (const Error& e) {
    GTEST_SKIP() << "no Vulkan backend: " << e.what();
  }
  PolygonMesh mesh = generate::translationalSurface(10, 10);
  mesh.vertices = test::perturbed(mesh.vertices, 0.01);
  for (const Method method : {Method::GaussNewton, Method::ShapeUp}) {
    Settings settings;
    settings.method = method;
    settings.tolerance = method == Method::GaussNewton ? 0.1 : 1.0;
    settings.maxIterations = 1000;
    expectAgreement(mesh, settings, *vulkan);
  }
}

}  // namespace
}  // namespace plano::planarize
