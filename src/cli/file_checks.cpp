#include "cli/file_checks.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>
#include <tuple>

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
  bool operator<(const FileId& o) const { return std::tie(dev, ino, name) < std::tie(o.dev, o.ino, o.name); }
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

// The file `path` names; for one that does not exist yet, the name it would get, with a dangling
// symbolic link followed to its target as the writer follows it.
std::optional<FileId> identity(std::string path) {
  for (int hops = 0; hops < 40; ++hops) {  // ELOOP's limit
    if (std::optional<FileId> id = existing(path)) return id;
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return destination(path);
    std::error_code ec;
    const std::filesystem::path to = std::filesystem::read_symlink(path, ec);
    if (ec) return std::nullopt;
    path = to.is_absolute() ? to.string() : (std::filesystem::path(path).parent_path() / to).string();
  }
  return std::nullopt;
}

std::string quoted(const FileArg& f) { return f.flag + " '" + f.path + "'"; }
std::string quoted(const FrameFile& f) { return f.flag + " '" + f.path + "'"; }

// How an input is named from an output's message: its frame when it is another frame's.
std::string input_of(const FrameFile& in, int out_frame) {
  if (in.frame == FrameFile::kEveryFrame) return quoted(in) + " (read by every frame)";
  return quoted(in) + (in.frame == out_frame ? "" : " of frame " + std::to_string(in.frame));
}

}  // namespace

void check_files(const std::vector<FileArg>& inputs, const std::vector<FileArg>& outputs) {
  std::vector<std::pair<const FileArg*, FileId>> read;
  std::optional<FileId> color;
  for (const FileArg& in : inputs) {
    if (in.path.empty()) continue;
    struct stat st {};
    if (::stat(in.path.c_str(), &st) != 0) continue;  // the reader names a missing file
    if (S_ISDIR(st.st_mode)) throw Error(quoted(in) + ": is a directory, not a file");
    if (!S_ISREG(st.st_mode)) throw Error(quoted(in) + ": is " + detail::non_regular_kind(in.path) + ", not a regular file");
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

void check_sequence_files(const std::vector<FrameFile>& inputs, const std::vector<FrameFile>& outputs) {
  std::map<FileId, std::vector<const FrameFile*>> read;
  for (const FrameFile& in : inputs)
    if (!in.path.empty())
      if (const std::optional<FileId> id = identity(in.path)) read[*id].push_back(&in);
  std::map<FileId, const FrameFile*> written;
  for (const FrameFile& out : outputs) {
    if (out.path.empty()) continue;
    const std::optional<FileId> id = identity(out.path);
    if (!id) continue;  // its folder is missing: the frame's own check names that
    const std::string frame = "frame " + std::to_string(out.frame) + ": ";
    if (const auto it = read.find(*id); it != read.end()) {
      bool in_place = false;  // --out is this frame's --color: its other inputs of this frame may be it too
      for (const FrameFile* in : it->second)
        in_place |= out.flag == "--out" && in->flag == "--color" && in->frame == out.frame;
      for (const FrameFile* in : it->second) {
        if (in_place && in->frame == out.frame) continue;
        throw Error(frame + quoted(out) + " is the same file as " + input_of(*in, out.frame) +
                    ": writing it would replace that input (only --out may name --color of its own frame, to fog "
                    "it in place)");
      }
    }
    const auto [it, fresh] = written.emplace(*id, &out);
    if (!fresh) {
      const FrameFile& other = *it->second;
      throw Error(frame + quoted(out) + " is the same file as " + quoted(other) +
                  (other.frame == out.frame ? "" : " of frame " + std::to_string(other.frame)) +
                  ": one output would replace the other");
    }
  }
}

}  // namespace fogcl::cli
