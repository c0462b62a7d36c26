#include "projbot/config/paths.hpp"

#include "projbot/config/output_file.hpp"

namespace projbot::config {

namespace fs = std::filesystem;

namespace {

std::string kind_of(const fs::file_status& st) {
  switch (st.type()) {
    case fs::file_type::not_found:
      return "does not exist";
    case fs::file_type::directory:
      return "is a folder, not a file";
    case fs::file_type::fifo:
      return "is a FIFO, not a regular file";
    case fs::file_type::socket:
      return "is a socket, not a regular file";
    case fs::file_type::character:
      return "is a character device, not a regular file";
    case fs::file_type::block:
      return "is a block device, not a regular file";
    case fs::file_type::regular:
      return "";
    default:
      return "is not a regular file";
  }
}

// The path with links and ".." resolved as far as it exists (the rest appended as written).
fs::path resolved(const fs::path& p) {
  std::error_code ec;
  fs::path r = fs::weakly_canonical(fs::absolute(p, ec), ec);
  if (ec) r = fs::absolute(p).lexically_normal();
  if (!r.has_filename() && r != r.root_path()) r = r.parent_path();  // "dir/" is "dir"
  return r;
}

bool inside_or_equal(const fs::path& p, const fs::path& folder) {
  auto f = folder.begin();
  auto q = p.begin();
  for (; f != folder.end(); ++f, ++q) {
    if (f->empty()) continue;  // a trailing separator
    if (q == p.end() || *q != *f) return false;
  }
  return true;
}

std::string quoted(const NamedPath& n) { return n.name + " " + n.path.string(); }

std::string inside_output(const NamedPath& out, const NamedPath& folder) {
  return quoted(out) + " is inside the output folder " + quoted(folder) + "; writing one would replace or mix with the other";
}

struct GeneratedAssets {
  fs::path shipped, generated;
};

GeneratedAssets& generated_assets() {
  static GeneratedAssets where;
  return where;
}

}  // namespace

void set_generated_assets(const fs::path& shipped, const fs::path& generated) {
  std::error_code ec;
  const fs::path s = fs::weakly_canonical(shipped, ec);
  generated_assets() = {ec ? shipped.lexically_normal() : s, generated.lexically_normal()};
}

fs::path beside_scene(const std::string& named, const fs::path& base) {
  const fs::path path(named);
  if (path.is_absolute()) return path;
  const fs::path here = base / path;
  const GeneratedAssets& g = generated_assets();
  std::error_code ec;
  if (g.generated.empty() || fs::exists(here, ec)) return here;
  const fs::path rel = fs::weakly_canonical(here, ec).lexically_relative(g.shipped);
  if (ec || rel.empty() || *rel.begin() == "..") return here;
  const fs::path made = g.generated / rel;
  return fs::exists(made, ec) ? made : here;
}

std::string input_file_problem(const fs::path& path) {
  std::error_code ec;
  return kind_of(fs::status(path, ec));
}

std::string input_folder_problem(const fs::path& path) {
  std::error_code ec;
  switch (fs::status(path, ec).type()) {
    case fs::file_type::directory:
      return "";
    case fs::file_type::not_found:
      return "no such folder";
    case fs::file_type::regular:
      return "is a file, not a folder";
    case fs::file_type::fifo:
      return "is a FIFO, not a folder";
    default:
      return "is not a folder";
  }
}

std::optional<std::string> find_path_clash(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const NamedPath& out = outputs[i];
    const fs::path o = resolved(out.path);
    for (const NamedPath& in : inputs) {
      const fs::path p = resolved(in.path);
      if (o == p) return quoted(out) + " is also the input " + quoted(in) + "; writing it would destroy the input";
      if (out.folder && inside_or_equal(p, o))
        return quoted(out) + " holds the input " + quoted(in) + "; name an output folder that holds no input";
      std::error_code ec;
      if (in.folder && inside_or_equal(o, p) && fs::exists(o, ec))
        return quoted(out) + " is inside the input folder " + quoted(in) +
               " and would replace part of it; write it outside that folder";
    }
    for (std::size_t j = 0; j < i; ++j) {
      const fs::path other = resolved(outputs[j].path);
      if (other == o) return quoted(out) + " and " + quoted(outputs[j]) + " are the same path; each output needs its own";
      // One output inside another's folder: writing the folder would replace or mix with the other.
      if (outputs[j].folder && inside_or_equal(o, other)) return inside_output(out, outputs[j]);
      if (out.folder && inside_or_equal(other, o)) return inside_output(outputs[j], out);
    }
  }
  return std::nullopt;
}

void check_replaceable_folder(const fs::path& folder, const std::set<std::string>& ours) {
  std::error_code ec;
  const auto st = fs::symlink_status(folder, ec);
  if (st.type() == fs::file_type::not_found) return;
  if (st.type() != fs::file_type::directory)
    throw OutputError(folder.string() + ": exists and is not a folder; name a new folder or one this command wrote");
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (!ours.contains(name) || entry.symlink_status(ec).type() != fs::file_type::regular)
      throw OutputError(folder.string() + ": holds '" + name +
                        "', which this command did not write; it replaces only a folder of its own output, so name a new "
                        "or empty folder");
  }
  if (ec) throw OutputError(folder.string() + ": cannot list it (" + ec.message() + ")");
}

}  // namespace projbot::config
