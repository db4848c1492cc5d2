// The files of one `fogcl apply` frame, checked before anything is read or written: no output may
// replace an input or another output, and every destination must be one fogcl can write.
#pragma once

#include <string>
#include <vector>

namespace fogcl::cli {

struct FileArg {
  std::string flag;  // "--color", "--png", ...
  std::string path;  // "" = not given
};

// Throws fogcl::Error, one line naming the flags and paths, when
// - an input is a directory ("--color 'shots': is a directory, not a file");
// - an output cannot be a destination (io/atomic_file.h's destination_problem: a missing folder,
//   a directory, FIFO, device or socket, a dangling symbolic link);
// - an output is the same file as an input or as another output. Files are compared by device and
//   inode, so symbolic links, hard links and other spellings of one file count as that file; an
//   output that does not exist yet is compared by its folder's device and inode and its name.
//   The only exception is fogging in place: --out may be the --color input.
void check_files(const std::vector<FileArg>& inputs, const std::vector<FileArg>& outputs);

}  // namespace fogcl::cli
