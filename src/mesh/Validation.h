#pragma once
// Validation of a polygon mesh before any algorithm runs on it: every problem found is
// collected with the face/vertex it concerns and a message saying what is wrong, so that
// a user can fix the file (or a caller can decide what to tolerate).
//
// Errors (the mesh is rejected by requireValid and by readMesh):
//   index_out_of_range        a face refers to a vertex that does not exist
//   too_few_vertices          a face of fewer than 3 vertices
//   repeated_vertex           a face visits a vertex twice
//   non_finite_coordinate     NaN or Inf
//   huge_coordinate           |x| beyond maxCoordinateMagnitude (squared lengths overflow)
//   non_manifold_edge         an edge shared by more than two faces
//   non_manifold_vertex       separate fans of faces meeting at one vertex
//   inconsistent_orientation  two faces traversing their shared edge in the same direction
//   zero_area_face            a face whose vector area vanishes
//   collinear_corners         three consecutive collinear corners, or two coincident ones,
//                             in a triangle or quad (a quad's diagonals then meet at a
//                             corner and no projective map is defined)
//   duplicate_face            two faces with the same vertex set
// Warnings (reported, the mesh is accepted):
//   isolated_vertex           a vertex in no face
//   collinear_corners         in faces of more than four corners (straight runs along an
//                             edge are common in panel layouts)
//
// Faces with a structural problem (the first three kinds) are left out of the later,
// geometric and topological checks, so one defect is reported once.
#include <cstddef>
#include <string>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano {

enum class Severity { Error, Warning };

enum class ValidationIssueKind {
  IndexOutOfRange,
  TooFewVertices,
  RepeatedVertex,
  NonFiniteCoordinate,
  HugeCoordinate,
  NonManifoldEdge,
  NonManifoldVertex,
  InconsistentOrientation,
  ZeroAreaFace,
  CollinearCorners,
  DuplicateFace,
  IsolatedVertex,
};

/// snake_case name of an issue kind (as used in JSON reports), e.g. "non_manifold_edge".
const char* toString(ValidationIssueKind kind);
const char* toString(Severity severity);

struct ValidationIssue {
  Severity severity = Severity::Error;
  ValidationIssueKind kind = ValidationIssueKind::IndexOutOfRange;
  Index face = -1;    ///< The face concerned, or -1.
  Index vertex = -1;  ///< The vertex concerned, or -1.
  std::string message;  ///< Names the element and the problem, e.g. "face 3 repeats vertex 7".
};

struct ValidationSettings {
  /// Coordinates beyond this magnitude are rejected: squared lengths of larger values
  /// overflow double precision or lose every significant digit of a planarity measure.
  double maxCoordinateMagnitude = 1e100;
  /// A face has zero area when |vector area| <= this * (perimeter)^2.
  double zeroAreaTolerance = 1e-14;
  /// Three corners a, b, c are collinear when sin(angle at b) <= this.
  double collinearSineTolerance = 1e-10;
  /// Issues stored per kind; further ones are only counted (a mesh of a million isolated
  /// vertices must not produce a million messages).
  std::size_t maxIssuesPerKind = 50;
};

enum class ValidationStatus { Valid, ValidWithWarnings, Invalid };

struct ValidationReport {
  ValidationStatus status = ValidationStatus::Valid;
  std::vector<ValidationIssue> issues;  ///< Errors first (in check order), then warnings.
  std::size_t errorCount = 0;           ///< All errors found, including those not stored.
  std::size_t warningCount = 0;         ///< All warnings found, including those not stored.

  bool valid() const { return errorCount == 0; }
};

/// Run every check on `mesh` (#V x 3 positions, faces of any degree) and collect the
/// issues. Never throws on malformed data: reporting it is the point.
ValidationReport validate(const PolygonMesh& mesh, const ValidationSettings& settings = {});

/// Throw Error(BadInput) when validate() finds an error. The message starts with `source`
/// (e.g. the file name) and lists the first few errors, e.g.
/// "mesh.obj: face 3 repeats vertex 7; vertex 9: coordinate x is NaN (and 4 more errors)".
void requireValid(const PolygonMesh& mesh, const std::string& source, const ValidationSettings& settings = {});

/// Throw Error(BadInput) as above when `report` has an error.
void requireValid(const ValidationReport& report, const std::string& source);

}  // namespace plano
