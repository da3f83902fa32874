#pragma once
// Wavefront OBJ: the polygon part of the format ("v" and "f" statements).
//
// Why not OpenMesh's OBJ reader and writer: its reader builds a half-edge mesh and drops
// faces it cannot add (non-manifold ones) with a message on stderr only, so a defective
// file is silently changed instead of reported with its line; its writer formats
// coordinates with a fixed precision. These strict streaming versions keep the polygons,
// the vertex and face order and every bit of every coordinate, and name file:line and
// the problem for every defect.
#include <string>
#include <string_view>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano::io {

/// Parse OBJ text. Supported: "v x y z [w | r g b [a]]", "f i i i ..." with 1-based or
/// negative (relative: -1 is the last vertex so far) indices and optional texture/normal
/// parts ("i/t", "i//n", "i/t/n", which are ignored), '#' comments, CRLF line ends and
/// '\' line continuations. Attributes and grouping statements (vt, vn, vp, g, o, s,
/// usemtl, mtllib, l, p, ...) are skipped; unknown statements are skipped with a warning.
/// Throws Error(BadInput) "SOURCE:LINE: problem" for malformed input: a bad number,
/// a non-finite coordinate, a face of fewer than 3 vertices, index 0, a relative index
/// before the first vertex, an index beyond the last vertex, binary data.
/// Out: vertices #V x 3 and faces in file order. Warnings are appended to `warnings`.
PolygonMesh parseObj(std::string_view text, const std::string& source, std::vector<std::string>* warnings = nullptr);

/// OBJ text of `mesh`: "v x y z" lines with shortest round-trip doubles, then "f" lines
/// with 1-based indices.
std::string formatObj(const PolygonMesh& mesh);

}  // namespace plano::io
