// Files that appear complete or not at all, even when the process is killed (kill -9) mid-write.
//
// Where the file system has it (Linux ext4, xfs, btrfs, tmpfs), the file is written as an unnamed
// O_TMPFILE inode in the target's folder and linked under its name only when complete: a killed
// writer leaves nothing, because the kernel frees an inode that has no name. Elsewhere (NFS, older
// kernels, or FOGCL_TEMP_FILES=named) it is written under 'TARGET.tmp-HOST-PID-N' and renamed onto
// the target; a kill -9 then leaves that name behind, and remove_stale_temporaries() sweeps it on
// the next run. HOST and PID say whose it is, so a sweep never takes the file of a writer that is
// still running, on this machine or on another machine sharing the folder.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace fogcl::detail {

// `body` writes the whole file into `out` (seekable; `name` names it in messages). On success the
// file appears at `path`, replacing what was there in one rename; on any failure nothing appears
// and a fogcl::Error "PATH: cannot write KIND: reason" is thrown.
void write_file_atomically(const std::string& path, const char* kind,
                           const std::function<void(std::ostream& out, const std::string& name)>& body);

// Removes the temporaries that write_file_atomically left in `dir` when a writer was killed:
// names 'TARGET.tmp-HOST-PID-N' with this machine's HOST, whose PID is no longer a running fogcl,
// and whose TARGET satisfies `ours` (a sequence sweeps its own outputs only). Returns how many.
int remove_stale_temporaries(const std::string& dir, const std::function<bool(const std::string& target)>& ours);

// "unnamed (O_TMPFILE)" or "named (TARGET.tmp-HOST-PID-N, swept when stale)": what
// write_file_atomically will use in `dir` (for --verbose).
std::string temporary_file_kind(const std::string& dir);

// Library messages may span lines; fogcl's file errors are one line.
std::string one_line(std::string s);

}  // namespace fogcl::detail
