// Files that appear complete or not at all, even when the process is killed (kill -9) mid-write.
//
// Where the file system has it (Linux ext4, xfs, btrfs, tmpfs), the file is written as an unnamed
// O_TMPFILE inode in the target's folder and linked under its name only when complete: a killed
// writer leaves nothing, because the kernel frees an inode that has no name. Elsewhere (NFS, older
// kernels, or FOGCL_TEMP_FILES=named) it is written under 'TARGET.tmp-HOST-PID-N' and renamed onto
// the target; a kill -9 then leaves that name behind, and remove_stale_temporaries() sweeps it on
// the next run. HOST and PID say whose it is, so a sweep never takes the file of a writer that is
// still running, on this machine or on another machine sharing the folder. A named temporary is
// also removed when SIGINT, SIGTERM or SIGHUP ends the process (remove_temporaries_on_signals).
//
// A destination that is a symbolic link is written through it: the file it names is replaced and
// the link stays. A destination that exists must be a regular file (a FIFO, device, directory or
// socket is refused, never replaced); the file that replaces it gets its permission bits and group
// (and, when run as root, its owner).
#pragma once

#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace fogcl::detail {

// `body` writes the whole file into `out` (seekable; `name` names it in messages). On success the
// file appears at `path`, replacing what was there in one rename; on any failure nothing appears
// and a fogcl::Error "PATH: cannot write KIND: reason" is thrown. While a WriteBatch is open on
// the calling thread the file is only prepared (written, flushed and closed under a temporary);
// the batch's commit() gives it its name.
void write_file_atomically(const std::string& path, const char* kind,
                           const std::function<void(std::ostream& out, const std::string& name)>& body);

// The outputs of one frame, all or none: while it is open on this thread, write_file_atomically
// prepares each file completely (a failure throws as usual) and commit() then names them all, in
// the order written (renames and links only, no writing). Destroyed before commit() (a later
// output failed), it removes every prepared temporary: no destination is replaced. One batch per
// thread at a time.
class WriteBatch {
 public:
  WriteBatch();
  ~WriteBatch();
  WriteBatch(const WriteBatch&) = delete;
  WriteBatch& operator=(const WriteBatch&) = delete;
  // Names every prepared file. If naming one fails (rare: a rename refused by the file system),
  // the files named before it stay, the rest are removed, and its error is thrown.
  void commit();

  struct Prepared;  // atomic_file.cpp

 private:
  friend void write_file_atomically(const std::string&, const char*,
                                    const std::function<void(std::ostream&, const std::string&)>&);
  std::vector<std::unique_ptr<Prepared>> prepared_;
};

// Why `path` cannot be a destination, "" when it can: "the folder 'DIR' does not exist", "'DIR' is
// not a folder", "it is a directory", "it is a FIFO (named pipe)", ..., "it is a symbolic link to
// 'X', which does not exist". Follows symbolic links, as the writer does.
std::string destination_problem(const std::string& path);

// What `path` is when it exists and is not a regular file: "a directory", "a FIFO (named pipe)",
// "a character device", "a block device", "a socket"; "" for a regular file or one that cannot be
// found (its reader names that). Follows symbolic links. Readers that need a file's size (EXR,
// JSON) refuse the others: a FIFO would block the open, /dev/zero never ends.
std::string non_regular_kind(const std::string& path);

// The file that write_file_atomically replaces for `path`: the file a symbolic link names (its
// canonical path), else `path`.
std::string resolved_destination(const std::string& path);

// The TARGET part of a named temporary's name for the file name `name` (no folder): `name` itself
// when 'NAME.tmp-HOST-PID-N' fits in NAME_MAX (255 bytes), else its first 137 bytes, '~' and 16
// hex digits of a hash of the whole name (so a 250-byte output name still gets a temporary).
std::string temporary_key(const std::string& name);
// Whether `key` is a shortened one (temporary_key of a long name); *head gets its leading bytes.
bool is_shortened_temporary_key(const std::string& key, std::string* head);

// Removes the temporaries that write_file_atomically left in `dir` when a writer was killed:
// names 'TARGET.tmp-HOST-PID-N' with this machine's HOST, whose PID is no longer a running fogcl,
// and whose TARGET (a temporary_key) satisfies `ours` (a sequence sweeps its own outputs only).
// Returns how many.
int remove_stale_temporaries(const std::string& dir, const std::function<bool(const std::string& target)>& ours);
// The same for single files: the stale temporaries of each of `paths` ("" entries are skipped),
// next to the file each resolves to.
int remove_stale_temporaries_of(const std::vector<std::string>& paths);

// Removes every named temporary of this process that exists now. Async-signal-safe: for signal
// handlers that end the process.
void remove_temporaries_now() noexcept;
// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove the named temporaries and then end
// the process by the same signal (its exit status unchanged).
void remove_temporaries_on_signals();

// "unnamed (O_TMPFILE)" or "named (TARGET.tmp-HOST-PID-N, swept when stale)": what
// write_file_atomically will use in `dir` (for --verbose).
std::string temporary_file_kind(const std::string& dir);

// Library messages may span lines; fogcl's file errors are one line.
std::string one_line(std::string s);

}  // namespace fogcl::detail
