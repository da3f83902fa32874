#pragma once
// Protection of the user's input file for every command that writes a mesh: writing the
// result over the input is refused unless the user asked for it (--in-place).
#include <string>

namespace plano::cli {

/// Throw Error(Usage) when `output` names the same file as `input` (compared after
/// canonicalization, so "./m.obj", "dir/../m.obj" and symbolic or hard links to the
/// same file all count as the same) and `inPlace` is false. An output that does not
/// exist yet is compared through its canonical folder. Empty paths are never equal.
void checkOutputPath(const std::string& input, const std::string& output, bool inPlace);

}  // namespace plano::cli
