#pragma once
// The small interface every algorithm of Plano is written against. A backend decides
// where a batched per-face kernel or a linear solve runs: the CPU reference (Eigen) or
// Vulkan compute shaders. Algorithms never branch on the backend.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "compute/DeviceMatrix.h"
#include "mesh/PolygonMesh.h"

namespace plano::compute {

enum class BackendKind { Cpu, Vulkan };

class AdmmSolver;     // compute/Admm.h
struct AdmmSettings;  // compute/Admm.h
class ReducedArapKernels;   // compute/ReducedArap.h
struct ReducedArapProblem;  // compute/ReducedArap.h

/// Compressed-row sparse matrix, the layout both backends consume.
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

/// Result of the batched local step (projective-maps paper, Eq. 3), one entry per face.
/// Row-vector convention: (p_i, 1) T_f = shat_i (q_i, 1), where shat_i = 1 / s_{f,i} is the
/// reciprocal scale factor of corner i; each T_f is scaled to mean shat_i 1 over its face
/// (projective::fitProjectiveMap says why not the paper's T_f(3, 3) = 1).
struct ProjectiveFits {
  std::vector<Eigen::Matrix4d> maps;      ///< #F maps.
  std::vector<double> reciprocalScales;   ///< One per corner, in the FaceList's CSR order.
  std::vector<double> residuals;          ///< Per face: RMS of the fit's equation residuals.
  std::vector<int> ranks;                 ///< Per face: numerical rank of the fit's system.
};

/// How a face's closest ideal map was found (Backend::closestIdealMaps).
enum class IdealMapMethod : std::int32_t {
  Jacobian = 0,          ///< From the fit's Jacobian at the face centroid, restricted to the face plane.
  /// The fit sends the centroid or a corner through the plane at infinity (its Jacobian
  /// says nothing about the face): Kabsch / Umeyama between source and target corners.
  CornerProcrustes = 1,
  /// As CornerProcrustes, but no target corners were given: no ideal map (the identity).
  CentroidAtInfinity = 2,
};

/// Result of the batched closest ideal maps, one entry per face.
struct IdealMaps {
  std::vector<Eigen::Matrix4d> maps;     ///< #F affine maps [[s R, 0], [t, 1]], T(3, 3) = 1.
  std::vector<IdealMapMethod> methods;   ///< #F.
};

/// Ideal maps a backend may keep where it computed them (Backend::fitIdealMapsOnDevice). They
/// are affine, [[s R, 0], [t, 1]]: their fourth columns (0, 0, 0, 1) need no storage.
struct DeviceIdealMaps {
  /// 4 #F x 3: rows 4 f .. 4 f + 3 hold the first three columns of face f's map (the
  /// stacking of the projective global step's unknowns, projective/GlobalStep.h).
  DeviceMatrix linearColumns;
  Index cornerProcrustes = 0;    ///< Faces whose map came from IdealMapMethod::CornerProcrustes.
  Index centroidsAtInfinity = 0; ///< Faces without an ideal map (IdealMapMethod::CentroidAtInfinity).
  Index firstCentroidAtInfinity = -1;  ///< The lowest such face, or -1.
};

/// Projective fits a backend may keep where it computed them
/// (Backend::fitProjectiveMapsOnDevice): what a global step and the positions after it read
/// of them, and the tallies of their induced reciprocal scales.
struct DeviceProjectiveFits {
  /// 4 #F x 3: rows 4 f .. 4 f + 3 hold the first three columns of face f's map.
  DeviceMatrix linearColumns;
  /// #corners x 1, FaceList CSR order: (p, 1) . a4 for corner c of face f, p the corner's
  /// source position and a4 the fourth column of f's map (the weight of the corner's image;
  /// projective::ShapeSpace::inducedReciprocalScales).
  DeviceMatrix reciprocalScales;
  Index nonPositiveScales = 0;      ///< Corners whose scale is <= 0 (or not a number).
  Index firstVanishingCorner = -1;  ///< The lowest corner with |scale| <= the limit asked for (or NaN); -1: none.
};

/// Which corners meet at each vertex (projective::ShapeSpace's tables).
struct VertexCorners {
  std::span<const Index> offsets;     ///< #V + 1: vertex v's corners are corners[offsets[v] .. offsets[v + 1]).
  std::span<const Index> corners;     ///< Corner indices, FaceList CSR order.
  std::span<const Index> cornerFace;  ///< Per corner, its face.
};

/// Backend::mapPositions's result.
struct MapPositions {
  DeviceMatrix positions;      ///< #V x 3, the base positions' coordinates.
  double displacement = 0.0;   ///< max over vertices of |positions - previous|.
  double maxPlanarity = 0.0;   ///< Largest face planarity at `positions` (percent, mesh/Planarity.h).
};

/// Backend::closestIdealMaps's input checks, one for every backend: Error(Usage) unless
/// `fitted` has one map per face and `target` (when given) as many rows as `source`.
void checkIdealMapInputs(const FaceList& faces, const Positions& source, std::span<const Eigen::Matrix4d> fitted,
                         const Positions* target);

/// Backend::fitProjectiveMaps's input check, one for every backend: Error(Usage) unless
/// `target` has as many rows as `source`.
void checkFitInputs(const Positions& source, const Positions& target);

/// Backend::mapPositions's input checks, one for every backend (Error(Usage)).
void checkMapPositionInputs(const FaceList& faces, const Positions& base, const VertexCorners& corners,
                            const DeviceMatrix& mapColumns, const DeviceMatrix& cornerWeights,
                            const DeviceMatrix& previous);

/// Settings of an iterative or direct SPD solve.
struct LinearSolverSettings {
  double relativeTolerance = 1e-10;  ///< Iterative solvers stop at ||r|| <= tol * ||b||.
  int maxIterations = 10000;         ///< Iterative solvers only.
  /// Direct solvers: measure ||A X - B|| / ||B|| for LinearSolveInfo::relativeResidual (a
  /// product with A per solve, which costs about what the triangular solves do). Loops that
  /// need only finiteness (the ADMM, the polish: relativeResidual then stays 0) turn it off.
  bool measureResidual = true;
  /// Iterative solvers: rows per block of the block-Jacobi preconditioner (1 to 4, dividing
  /// A's size; 1: Jacobi), as AdmmSettings::preconditionerBlock. Direct solvers ignore it.
  int preconditionerBlock = 1;
  /// Direct solvers: the most bytes their factor may take, checked after the symbolic
  /// analysis and before the factor is computed (OutOfMemory above it); 0: the memory
  /// available (core/Memory.h).
  std::uint64_t memoryLimitBytes = 0;
};

/// What the last solve did.
struct LinearSolveInfo {
  int iterations = 0;         ///< 1 for a direct solve.
  double relativeResidual = 0.0;
  bool converged = true;
};

/// Copies between host and device memory (Backend::transfers): what a loop meant to stay on
/// the device still moves.
struct DeviceTransfers {
  std::uint64_t uploadedBytes = 0;
  std::uint64_t downloadedBytes = 0;
  std::uint64_t copies = 0;  ///< Each one a synchronisation with the device.
};

/// The copies made between two readings of Backend::transfers (nullopt where either is).
std::optional<DeviceTransfers> transfersSince(const std::optional<DeviceTransfers>& before,
                                              const std::optional<DeviceTransfers>& after);

/// Solver for A X = B with A symmetric positive definite, A fixed at construction
/// (factored or uploaded once), many right-hand sides over its lifetime.
class SpdSolver {
 public:
  virtual ~SpdSolver() = default;
  /// Solve A X = B column by column. X holds a warm start on entry (iterative solvers
  /// use it; direct solvers ignore it) and the solution on exit.
  virtual LinearSolveInfo solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X) = 0;
  virtual Eigen::Index size() const = 0;
  /// Bytes a direct solver's factorization takes at its peak, as estimated from its
  /// symbolic analysis before the factor was computed (what LinearSolverSettings::
  /// memoryLimitBytes is checked against); 0 for a solver that does not factor.
  virtual double factorBytes() const { return 0.0; }
  /// Replace A by a matrix with the same sparsity pattern (precondition) and factor or
  /// upload it again, reusing what depends on the pattern only (a direct solver's ordering
  /// and symbolic analysis). Returns false when this solver cannot; the caller then creates
  /// a new one. For algorithms whose matrix changes every iteration (Gauss-Newton steps).
  virtual bool refactor(const SparseMatrix& A) {
    (void)A;
    return false;
  }
};

class Backend {
 public:
  virtual ~Backend() = default;

  virtual BackendKind kind() const = 0;
  /// Human-readable name, e.g. "cpu" or "vulkan (llvmpipe ...)".
  virtual std::string name() const = 0;

  /// Planarity (percent, Planarity.h definition) of every face; out has #F entries.
  virtual void facePlanarity(const PolygonMesh& mesh, std::span<double> out) = 0;

  /// Batched local step: the projective map of every face from `source` to `target`
  /// corners (both #V x 3), each face first projected onto its best-fitting plane; the
  /// solution closest to the identity when not unique, least squares when over-determined,
  /// both in coordinates centred at each face's own corner centroids (see LocalFit.h).
  virtual void fitProjectiveMaps(const FaceList& faces, const Positions& source, const Positions& target,
                                 ProjectiveFits& out) = 0;

  /// Batched orthogonal Procrustes (projective-maps paper, App. A): for each 3x3 matrix
  /// M = U S V^T, the closest rotation R = U diag(1, 1, d) V^T with d = det(U V^T), and
  /// the signed singular values (s1, s2, d * s3), so that R^T M = V diag(...) V^T.
  virtual void closestRotations(std::span<const Eigen::Matrix3d> matrices, std::span<Eigen::Matrix3d> rotations,
                                std::span<Eigen::Vector3d> singularValues) = 0;

  /// Batched closest ideal maps (projective-maps paper, App. A; the math of
  /// projective/IdealMapFit.h): for every face, the rigid (or, with `similar`, similarity)
  /// map closest to its fitted projective map `fitted[f]` from `source` corners (#V x 3,
  /// normalized coordinates), through the closest rotation of the fit's in-plane Jacobian at
  /// the face centroid; a fit that sends part of the face through the plane at infinity
  /// falls back to the corner-set Procrustes to `target` (#V x 3, the positions fitted to;
  /// may be null). `fitted` has #F entries (Error(Usage) otherwise).
  virtual void closestIdealMaps(const FaceList& faces, const Positions& source, std::span<const Eigen::Matrix4d> fitted,
                                const Positions* target, bool similar, IdealMaps& out) = 0;

  /// The local step of a rigid or similar deformation in one call: fitProjectiveMaps from
  /// `source` to `target`, then closestIdealMaps of those fits with `target` as the corner
  /// fallback's positions. The fits themselves are not returned: a device backend keeps
  /// them where the next kernel reads them instead of copying them to the host and back.
  /// The default runs the two calls.
  virtual void fitIdealMaps(const FaceList& faces, const Positions& source, const Positions& target, bool similar,
                            IdealMaps& out);

  /// fitIdealMaps with the maps left where they were computed: the host reads only the
  /// methods' tallies, and the maps when a caller reads linearColumns' values. The default
  /// runs fitIdealMaps and keeps its maps on the host.
  /// `target` may be a device matrix of this backend (mapPositions'): bound, not copied.
  virtual void fitIdealMapsOnDevice(const FaceList& faces, const Positions& source, const DeviceMatrix& target,
                                    bool similar, DeviceIdealMaps& out);

  /// fitProjectiveMaps with the maps left where they were computed, with each corner's
  /// induced reciprocal scale on `source` and their tallies (DeviceProjectiveFits): the
  /// host reads two numbers, and the maps or scales only when a caller reads their values.
  /// `target` may be a device matrix of this backend (mapPositions'): bound, not copied.
  /// The default runs fitProjectiveMaps and keeps everything on the host.
  virtual void fitProjectiveMapsOnDevice(const FaceList& faces, const Positions& source, const DeviceMatrix& target,
                                         double vanishingScale, DeviceProjectiveFits& out);

  /// Vertex positions of face maps given by their first three columns (4 #F x 3) and the
  /// weights of their corner images (#corners x 1, the fourth columns' contribution
  /// (p, 1) . a4: DeviceProjectiveFits::reciprocalScales; empty for affine maps, whose
  /// weights are 1); projective::ShapeSpace::normalizedPositions: each vertex the mean of
  /// its dehomogenized corner images (p, 1) A_f over the faces sharing it (p its row of
  /// `base`), an isolated vertex its base position; with the largest distance of a vertex
  /// from `previous` (#V x 3) and the largest planarity of `faces` there. A device backend
  /// keeps the positions on the device (two scalars come back) and binds inputs that are
  /// its own device matrices. Throws Error(Usage) for inputs of the wrong sizes,
  /// Error(Numerical) when a position is not finite.
  virtual void mapPositions(const FaceList& faces, const Positions& base, const VertexCorners& corners,
                            const DeviceMatrix& mapColumns, const DeviceMatrix& cornerWeights,
                            const DeviceMatrix& previous, MapPositions& out);

  /// A solver for the SPD system matrix A (prefactored or uploaded once).
  virtual std::unique_ptr<SpdSolver> createSpdSolver(const SparseMatrix& A, const LinearSolverSettings& settings) = 0;

  /// Whether createSpdSolver's solvers factor A (a solve then costs a pass over the factor
  /// whatever A's conditioning) rather than iterate (their cost grows with A's condition
  /// number). Algorithms that can pose a problem either as one stiff system or as a
  /// sequence of milder ones pick by it (projective/BoxQp.h, EqualitySolve).
  virtual bool factorsSpdMatrices() const { return false; }

  /// An ADMM solver for the box-constrained QPs min 1/2 x'Px + q'x s.t. l <= Cx <= u
  /// (compute/Admm.h), P and C uploaded or kept once. The default runs the iteration on
  /// the host with createSpdSolver's solver; a device backend keeps it on the device.
  virtual std::unique_ptr<AdmmSolver> createAdmmSolver(const SparseMatrix& P, const SparseMatrix& C,
                                                       const AdmmSettings& settings);

  /// Device kernels for subspace ASAP/ARAP iterations (compute/ReducedArap.h), or null
  /// when this backend has none: the algorithm then runs its host kernels. `problem` is
  /// called only by a backend that uses it (building it costs O(d^2 #V) on the host).
  virtual std::unique_ptr<ReducedArapKernels> createReducedArapKernels(
      const std::function<ReducedArapProblem()>& problem);

  /// The reduced operator N^T (S (x) I_k) N of a linear space's basis (compute/
  /// ReducedOperator.h: N has k #V rows, row k v + c coordinate c of vertex v; S is
  /// #V x #V; the result d x d). A device backend uploads N and S and brings back the d x d
  /// result only. Throws Error(Usage) for mismatched sizes. The default is the CPU reference.
  virtual Eigen::MatrixXd reducedOperator(const SparseMatrix& S, const Eigen::MatrixXd& N, int coordinates);

  /// Host <-> device copies since this backend was created; nullopt for a backend whose
  /// data never leaves the host (the CPU).
  virtual std::optional<DeviceTransfers> transfers() const { return std::nullopt; }
};

/// Which backend the user asked for.
enum class BackendChoice { Cpu, Vulkan, Auto };

/// Parse "cpu", "vulkan" or "auto"; throws Error(Usage) otherwise.
BackendChoice parseBackendChoice(const std::string& text);

/// Create a backend. Vulkan failures throw Error(Device) when Vulkan was asked for; with
/// Auto, Vulkan is used only on a real (non-CPU) GPU and any failure falls back to the CPU
/// with a warning written to `warnings` (when not null).
std::unique_ptr<Backend> createBackend(BackendChoice choice, std::string* warnings = nullptr);

}  // namespace plano::compute
