#pragma once
// Stanford PLY, ASCII and binary (little and big endian).
//
// Why not OpenMesh's PLY reader: it adds faces to a half-edge mesh and drops the ones it
// cannot add (non-manifold), it answers a malformed file with a bare "false", and it has no
// way to say which property is unsupported. This reader parses the header into elements
// and properties, reads every element (skipping the ones a mesh does not need, of any
// scalar or list type), and checks the declared sizes against the bytes actually present
// before allocating anything.
#include <string>
#include <string_view>
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano::io {

enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

/// Parse PLY data. Vertices come from the element "vertex" (scalar properties x, y, z of
/// any numeric type; other properties skipped), faces from the element "face" (a list
/// property "vertex_indices" or "vertex_index" with integer count and item types; other
/// properties skipped). Other elements (edges, materials, ...) are skipped.
/// Throws Error(BadInput) "SOURCE[:LINE]: problem" for a missing or malformed header, an
/// unsupported property (e.g. face indices of type float, a list-typed coordinate), a
/// truncated body or extra data after it, non-finite coordinates, faces of fewer than
/// 3 vertices and out-of-range indices.
PolygonMesh parsePly(std::string_view data, const std::string& source, std::vector<std::string>* warnings = nullptr);

/// PLY data of `mesh`: double x, y, z and a list (uchar count, or int count for faces of
/// more than 255 corners) of int vertex_indices. Binary encodings are exact; ASCII uses
/// shortest round-trip doubles, so it is exact too.
std::string formatPly(const PolygonMesh& mesh, PlyEncoding encoding = PlyEncoding::BinaryLittleEndian);

}  // namespace plano::io
