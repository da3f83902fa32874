#pragma once
// Protection of the user's files for every command that writes one: writing a result over
// an input is refused unless the user asked for it (--in-place), a run whose outputs cannot
// be written (a folder that does not exist, a target that is a folder, an unknown mesh
// format) is refused before it starts, not after a long computation, and the files of one
// run are written together: all of them or, when one fails, none.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace plano::cli {

/// A file a command writes, with the option that names it (for messages).
struct WrittenFile {
  std::string option;  ///< "--output", "--primal", "--report".
  std::string path;    ///< Empty: not given (or given empty, see `given`).
  bool given = false;  ///< The option was on the command line, even with an empty value.
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

/// Throw Error(Usage), before a command runs, when a written file is given empty, cannot be
/// written where it resolves (resolveOutput), goes to a folder that does not exist or cannot
/// be written, is a mesh (--output, --primal) whose extension names no mesh format, names
/// an input file (compared after canonicalization, so "./m.obj", "dir/../m.obj" and
/// symbolic or hard links to one file are the same; only the result mesh may name the mesh,
/// and only with inPlace), or is another written file.
void checkCommandPaths(const CommandPaths& paths);

/// Where a written file really goes.
struct OutputTarget {
  std::filesystem::path path;  ///< The file a symbolic link resolves to, or the path itself.
  /// A FIFO or character device (/dev/null, /dev/stdout): written to directly. It is no
  /// regular file that a temporary one could replace, and replacing the node would break
  /// whoever reads from it.
  bool stream = false;
};

/// The target of writing `path`: a symbolic link is followed (to the file it names, which
/// need not exist yet), so that the link stays a link to the new content. Throws
/// Error(Usage) for a folder, a socket, a block device and a link loop.
OutputTarget resolveOutput(const std::string& path);

/// The files of one run, written together by commit(): each regular file to a temporary
/// file next to its target, and only once every one is complete are they renamed over
/// their targets, so that a failed write leaves all of them as they were. Until the last
/// rename each target's old file is kept under a hard link (".NAME.oldPID-RANDOM"): a
/// rename that fails midway puts back the files renamed before it (or removes those that
/// did not exist), except on a file system without hard links. Streams
/// (OutputTarget::stream) cannot be written atomically and are written last, after the
/// renames. Temporary files are named ".NAME.tmpPID-RANDOM".
class OutputFiles {
 public:
  /// `interruptible`: commit() stops, removing its temporary files and throwing
  /// plano::Interrupted, when cancellation is requested (core/Cancellation.h) before the
  /// renames. A run's results are; the report of an interrupted run is not.
  explicit OutputFiles(bool interruptible = false) : interruptible_(interruptible) {}

  void add(std::string path, std::string content);
  bool empty() const { return files_.empty(); }

  /// Write every file added. Throws Error(BadInput) naming the file that could not be
  /// written (every target then as it was, unless a stream failed midway).
  void commit();

  /// Called with each staged file's index before its rename (tests make one fail there).
  void setBeforeRename(std::function<void(std::size_t)> hook) { beforeRename_ = std::move(hook); }

 private:
  struct File {
    std::string path;
    std::string content;
  };
  std::vector<File> files_;
  bool interruptible_;
  std::function<void(std::size_t)> beforeRename_;
};

}  // namespace plano::cli
