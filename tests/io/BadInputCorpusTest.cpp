// Every file of tests/data/bad must be refused with exit code 3 (bad input) by `plano
// info` and with Error(BadInput) by the library reader, and the message must name the
// specific problem.
#include <gtest/gtest.h>

#include <set>

#include "core/Error.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

struct BadFile {
  const char* name;
  const char* message;  ///< A substring the error message must contain.
};

const BadFile kBadFiles[] = {
    {"binary_garbage.obj", ":1: binary data (byte 0x7f) in a text file"},
    {"binary_garbage.off", ":1: binary data (byte 0x7f) in a text file"},
    {"binary_garbage.ply", ":1: binary data (byte 0x7f) in a text file"},
    {"empty.obj", "empty.obj: file is empty"},
    {"empty.off", "empty.off: file is empty"},
    {"whitespace_only.obj", "file contains only whitespace"},
    {"whitespace_only.off", "file contains only whitespace"},
    {"obj_bad_corner_syntax.obj", ":5: face corner '1/1/1/1' has more than three '/'-separated parts"},
    {"obj_face_two_vertices.obj", ":5: face has 2 vertices (at least 3 needed)"},
    {"obj_index_out_of_range.obj", ":6: face 1: vertex index 9 out of range (the file has 4 vertices)"},
    {"obj_index_zero.obj", ":5: vertex index 0 is invalid (OBJ indices start at 1)"},
    {"obj_nan_coordinate.obj", ":3: vertex coordinate 'NaN' is not finite"},
    {"obj_non_manifold_edge.obj", "edge (0, 1) is shared by 3 faces (0, 1, 2): non-manifold edge"},
    {"obj_not_a_number.obj", ":3: vertex coordinate 'one' is not a number"},
    {"obj_only_vertices.obj", "no faces (4 vertices and no polygon)"},
    {"obj_relative_index_before_first_vertex.obj",
     ":5: relative vertex index -5 refers before the first vertex (4 vertices defined so far)"},
    {"obj_vertex_two_coordinates.obj", ":1: vertex has 2 coordinates (3 needed)"},
    {"off_collinear_quad.off", "face 0: corners 0, 1, 2 (vertices 0, 1, 2) are collinear"},
    {"off_counts_not_integers.off", ":2: vertex count '6.5' is not an integer"},
    {"off_duplicate_face.off", "face 1 duplicates face 0 (same vertices)"},
    {"off_face_size_disagrees_with_indices.off", ":9: face 0: 2 values after its vertex indices"},
    {"off_face_two_vertices.off", ":10: face 1 has 2 vertices (at least 3 needed)"},
    {"off_header_declares_fewer_faces.off", ":10: unexpected data '4' after the 1 faces declared in the header"},
    {"off_header_declares_more_faces.off", ":11: file ends after 2 of the 3 faces declared in the header"},
    {"off_huge_coordinate.off", "vertex 1: coordinate x = 1e+308 exceeds 1e+100 in magnitude"},
    {"off_huge_count_tiny_body.off", ":4: file ends after 1 of the 2000000000 vertices declared in the header"},
    {"off_inconsistent_orientation.off",
     "edge (1, 4): faces 0 and 1 both traverse it from 1 to 4 (inconsistent orientation)"},
    {"off_index_out_of_range.off", ":10: face 1: vertex index 9 out of range [0, 6)"},
    {"off_inf_coordinate.off", ":5: vertex coordinate '-inf' is not finite"},
    {"off_missing_header.off", ":1: not an OFF file: expected the header 'OFF', found '6'"},
    {"off_nan_coordinate.off", ":4: vertex coordinate 'nan' is not finite"},
    {"off_negative_index.off", ":10: face 1: negative vertex index -1"},
    {"off_no_faces.off", "no faces (3 vertices and no polygon)"},
    {"off_non_manifold_edge.off", "edge (0, 1) is shared by 3 faces (0, 1, 2): non-manifold edge"},
    {"off_non_manifold_vertex.off", "vertex 0 is non-manifold: its faces form 2 separate fans"},
    {"off_one_based_indices.off", ":11: face 1: vertex index 6 out of range [0, 6): indices look 1-based"},
    {"off_overflowing_coordinate.off", ":4: vertex coordinate '1e400' is out of the range of double precision"},
    {"off_repeated_vertex.off", "face 0 repeats vertex 1"},
    {"off_truncated.off", ":8: file ends after 5 of the 6 vertices declared in the header (truncated file"},
    {"off_very_long_line.off", ":6: vertex coordinate '7777777777777777777777777777777777777777...' is not a number"},
    {"off_zero_area_face.off", "face 0 has zero area"},
    {"ply_extra_data_after_body.ply", ":15: unexpected data after the last element declared in the header"},
    {"ply_face_two_vertices.ply", ":14: face 0 has 2 vertices (at least 3 needed)"},
    {"ply_float_face_indices.ply", ":8: face property 'vertex_indices' is a list of floating-point values: unsupported"},
    {"ply_huge_count_tiny_body.ply", "declares 1000000000 'vertex' elements of at least 6 bytes each, but only 24 bytes"},
    {"ply_index_out_of_range.ply", ":14: face 0: vertex index 4 out of range [0, 4)"},
    {"ply_missing_end_header.ply", ":7: file ends inside the header (no 'end_header' line)"},
    {"ply_missing_z.ply", ":3: the 'vertex' element has no 'z' property"},
    {"ply_not_ply.ply", ":1: not a PLY file: the first line must be 'ply'"},
    {"ply_truncated_binary.ply", "declares 4 'vertex' elements of at least 24 bytes each, but only 48 bytes follow"},
    {"ply_unknown_format.ply", ":2: unknown PLY format 'binary_middle_endian'"},
    {"ply_unknown_property_type.ply", ":4: unknown property type 'float128'"},
};

std::filesystem::path badDir() { return std::filesystem::path(PLANO_TEST_DATA_DIR) / "bad"; }

class BadInputCorpus : public ::testing::TestWithParam<BadFile> {};

TEST_P(BadInputCorpus, LibraryReaderThrowsBadInputNamingTheProblem) {
  const BadFile& bad = GetParam();
  try {
    readMesh(badDir() / bad.name);
    FAIL() << bad.name << " was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find(bad.message), std::string::npos) << e.what();
    EXPECT_LT(std::string(e.what()).size(), 1000u) << "messages stay short whatever the input";
  }
}

TEST_P(BadInputCorpus, InfoCommandExitsWithCode3AndTheMessage) {
  const BadFile& bad = GetParam();
  const auto result = test::runTool("info " + (badDir() / bad.name).string());
  EXPECT_EQ(result.exitCode, 3) << result.err;
  EXPECT_NE(result.err.find(bad.message), std::string::npos) << result.err;
  EXPECT_TRUE(result.out.empty()) << result.out;
}

INSTANTIATE_TEST_SUITE_P(Files, BadInputCorpus, ::testing::ValuesIn(kBadFiles), [](const auto& info) {
  std::string name = info.param.name;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
});

TEST(BadInputCorpusFiles, EveryFileHasAnExpectation) {
  std::set<std::string> listed;
  for (const auto& bad : kBadFiles) listed.insert(bad.name);
  std::set<std::string> present;
  for (const auto& entry : std::filesystem::directory_iterator(badDir())) present.insert(entry.path().filename());
  EXPECT_EQ(listed, present);
}

}  // namespace
}  // namespace plano
