#pragma once
// Protection of the user's files for every command that writes one: writing a result over
// an input is refused unless the user asked for it (--in-place), and a run whose output
// folder does not exist is refused before it starts, not after a long computation.
#include <string>
#include <vector>

namespace plano::cli {

/// A file a command writes, with the option that names it (for messages).
struct WrittenFile {
  std::string option;  ///< "--output", "--primal", "--report".
  std::string path;    ///< Empty: not given.
};

/// The files a command reads and writes, as its options name them (main.cpp gathers them
/// from every command's options by name).
struct CommandPaths {
  std::vector<std::string> inputs;  ///< The mesh first, then the other files read.
  std::vector<WrittenFile> outputs;  ///< The result mesh (--output) first.
  bool inPlace = false;              ///< --in-place given: the result mesh may be the mesh itself.
  bool inPlaceOption = false;        ///< The command has --in-place (messages suggest it only then).

  /// The file of --report, or empty.
  std::string report() const;
};

/// Throw Error(Usage), before a command runs, when a written file goes to a folder that
/// does not exist or cannot be written, names an input file (compared after
/// canonicalization, so "./m.obj", "dir/../m.obj" and symbolic or hard links to one file
/// are the same; only the result mesh may name the mesh, and only with inPlace), or is
/// another written file.
void checkCommandPaths(const CommandPaths& paths);

}  // namespace plano::cli
