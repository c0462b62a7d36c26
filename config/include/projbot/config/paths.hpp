#pragma once
// A command's inputs against its outputs, before any work: an output that names an input (after
// resolving links), an output folder that holds an input, two outputs on one path, and inputs that are
// not regular files (a FIFO blocks open(), /dev/zero never ends). Also which folders an output may replace.

#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace projbot::config {

/// A path a command reads or writes, named for messages ("--scene", "the default scene").
struct NamedPath {
  std::string name;
  std::filesystem::path path;
  bool folder = false;  ///< the command reads or writes a folder's contents
};

/// A file or folder as a scene in folder `base` names it: absolute, or relative to `base`. Files the build
/// makes for the shipped scenes (the content scene's video) live in the build tree, never beside the
/// shipped files: a relative name that resolves inside the shipped asset folder and is not there is looked
/// for at the same place under the generated one (set_generated_assets), and taken from there if it is.
std::filesystem::path beside_scene(const std::string& named, const std::filesystem::path& base);

/// Where the build puts what it makes for the files under `shipped` (the executable sets this once, at
/// its start, before any scene is read). Unset, beside_scene() only looks beside the scene.
void set_generated_assets(const std::filesystem::path& shipped, const std::filesystem::path& generated);

/// Why `path` cannot be read as a file ("does not exist", "is a folder, not a file", "is a FIFO, not a
/// regular file", ...), or empty when it is a regular file (links followed).
std::string input_file_problem(const std::filesystem::path& path);

/// The same for a folder a command reads: "no such folder", "is a file, not a folder", "is a FIFO, not a
/// folder", ..., or empty when it is a folder (links followed).
std::string input_folder_problem(const std::filesystem::path& path);

/// The first clash between `inputs` and `outputs`, as one line naming both, or nothing:
/// - an output on the same file as an input or another output, or inside another output's folder;
/// - an input inside (or equal to) an output folder, which the output would replace or mix into;
/// - an output file that exists inside an input folder (it would replace part of the input).
/// Paths are compared after resolving links and "..", so a link to the scene is the scene.
std::optional<std::string> find_path_clash(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs);

/// Throws OutputError unless `folder` may be replaced by an output made of files named `ours`: it does not
/// exist, is empty, or holds only regular files with those names (a previous run's output). A folder
/// with anything else in it is refused, never emptied; the message names one thing that is in the way.
void check_replaceable_folder(const std::filesystem::path& folder, const std::set<std::string>& ours);

}  // namespace projbot::config
