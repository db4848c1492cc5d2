// The files of a `fogcl apply` run, checked before anything is read or written: no output may
// replace an input or another output, every input is a regular file, and every destination must be
// one fogcl can write.
#pragma once

#include <string>
#include <vector>

namespace fogcl::cli {

struct FileArg {
  std::string flag;  // "--color", "--png", ...
  std::string path;  // "" = not given
};

// Throws fogcl::Error, one line naming the flags and paths, when
// - an input exists and is not a regular file ("--color 'shots': is a directory, not a file",
//   "--volumes '/dev/zero': is a character device, not a regular file"; a FIFO is refused without
//   being opened, so nothing blocks);
// - an output cannot be a destination (io/atomic_file.h's destination_problem: a missing folder,
//   a directory, FIFO, device or socket, a dangling symbolic link);
// - an output is the same file as an input or as another output. Files are compared by device and
//   inode, so symbolic links, hard links and other spellings of one file count as that file; an
//   output that does not exist yet is compared by its folder's device and inode and its name.
//   The only exception is fogging in place: --out may be the --color input.
void check_files(const std::vector<FileArg>& inputs, const std::vector<FileArg>& outputs);

// A file of a frame sequence: `frame` is its frame number, kEveryFrame for a file that every frame
// reads (a --depth without placeholder, --volumes, --shadow-map).
struct FrameFile {
  static constexpr int kEveryFrame = -1;
  std::string flag;
  int frame = kEveryFrame;
  std::string path;  // "" = not given
};

// The whole run at once, before its first frame is read: every output of every frame against every
// input of every frame and every other output, as check_files compares them (device and inode; a
// file that does not exist yet, input or output, by its folder's device and inode and its name,
// symbolic links followed). So frame 1's output cannot replace the input of frame 10 (or create
// the depth file frame 10 would then read). Fogging in place stays allowed: --out of frame F may be
// --color of frame F (and another input of frame F). Throws fogcl::Error, one line:
// "frame 1: --out 'seq/color.0010.exr' is the same file as --color 'seq/color.0010.exr' of frame
// 10: ...". Costs a stat or two per file: nothing is opened.
void check_sequence_files(const std::vector<FrameFile>& inputs, const std::vector<FrameFile>& outputs);

}  // namespace fogcl::cli
