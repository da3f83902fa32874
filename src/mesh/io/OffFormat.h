#pragma once
// Object File Format (OFF, Geomview), ASCII.
//
// Why not OpenMesh's OFF reader: it drops faces it cannot add to its half-edge mesh
// (non-manifold ones) and reports malformed files with a bare "false", so neither the
// defect nor its line reaches the user; a 1-based file (a common real-world defect) would
// load shifted by one vertex or fail without saying why. This strict streaming reader
// keeps faces as they are and names file:line and the problem.
#include <string>
#include <string_view>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano::io {

/// Parse OFF text: a header keyword OFF (or COFF, NOFF, CNOFF, STOFF, STCOFF, ...: the
/// per-vertex extras are skipped), the counts "V F [E]" (on the header line or the next),
/// V vertices "x y z [extras]" and F faces "n i_1 ... i_n [colour]" with 0-based indices.
/// A face may wrap across lines; anything after its n indices on its last line is its
/// colour (0, 1, 3 or 4 numbers). '#' comments and CRLF line ends are allowed.
/// Throws Error(BadInput) "SOURCE:LINE: problem" for malformed input: a missing or unknown
/// header, counts that are not integers or disagree with the body (truncated file or
/// extra data), bad numbers, non-finite coordinates, faces of fewer than 3 vertices,
/// negative or out-of-range indices (saying when the indices look 1-based), binary data.
/// Never reserves more memory than the text can fill, whatever the header declares.
PolygonMesh parseOff(std::string_view text, const std::string& source, std::vector<std::string>* warnings = nullptr);

/// OFF text of `mesh` ("OFF", "V F 0", vertices with shortest round-trip doubles, faces).
std::string formatOff(const PolygonMesh& mesh);

}  // namespace plano::io
