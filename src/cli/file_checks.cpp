#include "cli/file_checks.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <optional>

#include "fogcl/error.h"
#include "io/atomic_file.h"

namespace fogcl::cli {

namespace {

// What identifies a file: its device and inode, or, for an output that does not exist yet, its
// folder's device and inode and its name.
struct FileId {
  dev_t dev = 0;
  ino_t ino = 0;
  std::string name;  // "" for an existing file
  bool operator==(const FileId& o) const { return dev == o.dev && ino == o.ino && name == o.name; }
};

std::optional<FileId> existing(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::nullopt;
  return FileId{st.st_dev, st.st_ino, ""};
}

std::optional<FileId> destination(const std::string& path) {
  if (std::optional<FileId> id = existing(path)) return id;
  const std::filesystem::path p(path);
  std::optional<FileId> dir = existing(p.has_parent_path() ? p.parent_path().string() : ".");
  if (dir) dir->name = p.filename().string();
  return dir;
}

std::string quoted(const FileArg& f) { return f.flag + " '" + f.path + "'"; }

}  // namespace

void check_files(const std::vector<FileArg>& inputs, const std::vector<FileArg>& outputs) {
  std::vector<std::pair<const FileArg*, FileId>> read;
  std::optional<FileId> color;
  for (const FileArg& in : inputs) {
    if (in.path.empty()) continue;
    struct stat st {};
    if (::stat(in.path.c_str(), &st) != 0) continue;  // the reader names a missing file
    if (S_ISDIR(st.st_mode)) throw Error(quoted(in) + ": is a directory, not a file");
    read.push_back({&in, FileId{st.st_dev, st.st_ino, ""}});
    if (in.flag == "--color") color = read.back().second;
  }
  std::vector<std::pair<const FileArg*, FileId>> written;
  for (const FileArg& out : outputs) {
    if (out.path.empty()) continue;
    if (const std::string problem = detail::destination_problem(out.path); !problem.empty())
      throw Error(quoted(out) + ": " + problem);
    const std::optional<FileId> id = destination(out.path);
    if (!id) continue;
    for (const auto& [in, in_id] : read) {
      if (!(in_id == *id)) continue;
      if (out.flag == "--out" && color && *color == *id) break;  // fogging --color in place
      throw Error(quoted(out) + " is the same file as " + quoted(*in) +
                  ": writing it would replace that input (only --out may name --color, to fog it in place)");
    }
    for (const auto& [other, other_id] : written)
      if (other_id == *id)
        throw Error(quoted(out) + " is the same file as " + quoted(*other) + ": one output would replace the other");
    written.push_back({&out, *id});
  }
}

}  // namespace fogcl::cli
