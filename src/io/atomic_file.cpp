#include "io/atomic_file.h"

#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <new>
#include <streambuf>
#include <system_error>
#include <vector>

#include "fogcl/error.h"

namespace fogcl {

namespace detail {

namespace {

// A seekable output buffer over a file descriptor: std::ofstream cannot open an O_TMPFILE inode.
// tellp() (seekoff(0, cur)) does not flush: OpenEXR asks for the position at every chunk.
class FdBuf : public std::streambuf {
 public:
  explicit FdBuf(int fd) : fd_(fd), buf_(std::size_t(1) << 20) { setp(buf_.data(), buf_.data() + buf_.size()); }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return drain() ? 0 : -1; }
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode) override {
    if (dir == std::ios_base::cur && off == 0) return pos_type(off_type(pos_ + (pptr() - pbase())));
    if (!drain()) return pos_type(off_type(-1));
    const off_t at = ::lseek(fd_, off_t(off), dir == std::ios_base::beg ? SEEK_SET : dir == std::ios_base::cur ? SEEK_CUR : SEEK_END);
    if (at < 0) {
      error_ = errno;
      return pos_type(off_type(-1));
    }
    pos_ = at;
    return pos_type(off_type(at));
  }
  pos_type seekpos(pos_type p, std::ios_base::openmode which) override {
    return seekoff(off_type(p), std::ios_base::beg, which);
  }

 private:
  bool drain() {
    for (const char* p = pbase(); p < pptr();) {
      const ssize_t n = ::write(fd_, p, std::size_t(pptr() - p));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        error_ = n < 0 ? errno : EIO;
        return false;
      }
      p += n;
    }
    pos_ += pptr() - pbase();
    setp(buf_.data(), buf_.data() + buf_.size());
    return true;
  }

  int fd_;
  std::vector<char> buf_;
  off_t pos_ = 0;  // file offset of pbase()
  int error_ = 0;
};

std::string parent_dir(const std::string& path) {
  const std::string parent = std::filesystem::path(path).parent_path().string();
  return parent.empty() ? std::string(".") : parent;
}

// This machine's name as it appears in temporary names: [A-Za-z0-9._-] only.
const std::string& host_tag() {
  static const std::string tag = [] {
    char name[256] = {};
    if (::gethostname(name, sizeof name - 1) != 0 || name[0] == 0) return std::string("localhost");
    std::string s(name);
    if (s.size() > 64) s.resize(64);  // a temporary's name must leave room for the target's
    for (char& c : s)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-')) c = '_';
    return s;
  }();
  return tag;
}

// ".tmp-" HOST "-" PID "-" N at its longest: HOST <= 64 bytes, PID <= 10 digits, N <= 20 digits.
constexpr std::size_t kTempSuffixMax = 5 + 64 + 1 + 10 + 1 + 20;
constexpr std::size_t kNameMax = NAME_MAX;                   // 255 on Linux
constexpr std::size_t kKeyMax = kNameMax - kTempSuffixMax;   // 154
constexpr std::size_t kHashDigits = 16;
constexpr std::size_t kKeyHead = kKeyMax - 1 - kHashDigits;  // 137

std::string temp_name(const std::string& path) {
  // Unique per machine (host), process (pid) and call (counter): concurrent writers never share one.
  static std::atomic<unsigned long> counter{0};
  const std::filesystem::path p(path);
  const std::string key = temporary_key(p.filename().string());
  const std::string name = key + ".tmp-" + host_tag() + "-" + std::to_string(long(::getpid())) + "-" +
                           std::to_string(counter++);
  return p.has_parent_path() ? (p.parent_path() / name).string() : name;
}

// ---- Named temporaries that a signal handler removes ----------------------------------------------
//
// A fixed table that a handler can walk without locks or allocation: a slot is free (0), being
// filled (1) or holds a live name (2). Only slots in state 2 are unlinked. A name read while its
// slot is being reused could be torn, but every name here ends in '.tmp-HOST-PID-N' with this
// process's PID, so even a torn one names nothing but a temporary of this process.
constexpr int kSlots = 64;
struct TempSlot {
  std::atomic<int> state{0};
  char name[PATH_MAX];
};
TempSlot g_slots[kSlots];

int register_temporary(const std::string& name) {
  if (name.size() >= PATH_MAX) return -1;  // left to the next run's sweep
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (!g_slots[i].state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(g_slots[i].name, name.c_str(), name.size() + 1);
    g_slots[i].state.store(2);
    return i;
  }
  return -1;  // more than kSlots at once: never in fogcl (two per frame)
}

void unregister_temporary(int& slot) {
  if (slot >= 0) g_slots[slot].state.store(0);
  slot = -1;
}

extern "C" void remove_temporaries_and_die(int signo) {
  remove_temporaries_now();
  ::signal(signo, SIG_DFL);
  ::raise(signo);  // delivered when the handler returns: the process ends by this signal
}

// "a FIFO (named pipe)" etc. for a file that is not a regular file.
const char* file_type_name(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::uint64_t fnv1a64(const std::string& s) {
  std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a, 64-bit offset basis and prime
  for (unsigned char c : s) h = (h ^ c) * 0x100000001b3ull;
  return h;
}

// An unnamed file in `dir`, or -1 where the file system (or FOGCL_TEMP_FILES=named) says no.
int open_unnamed(const std::string& dir) {
  const char* mode = std::getenv("FOGCL_TEMP_FILES");
  if (mode != nullptr && std::string(mode) == "named") return -1;
  return ::open(dir.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
}

// Gives the unnamed inode of `fd` the name `target`; false with errno set on failure (EEXIST when
// the name is taken: linkat never replaces). AT_EMPTY_PATH needs CAP_DAC_READ_SEARCH; /proc does not.
bool link_unnamed(int fd, const std::string& target) {
  if (::linkat(fd, "", AT_FDCWD, target.c_str(), AT_EMPTY_PATH) == 0) return true;
  if (errno == EEXIST) return false;
  const std::string proc = "/proc/self/fd/" + std::to_string(fd);
  return ::linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, target.c_str(), AT_SYMLINK_FOLLOW) == 0;
}

std::string error_text(int err) { return std::strerror(err != 0 ? err : EIO); }

// Whether `pid` may still be a fogcl writing its temporary: this process, or a live process with
// our command name. Unsure (no /proc) counts as running: a sweep never takes a live writer's file.
bool may_be_running_fogcl(long pid) {
  if (pid == long(::getpid())) return true;
  if (::kill(pid_t(pid), 0) != 0 && errno == ESRCH) return false;
  const auto comm = [](const std::string& p) {
    std::ifstream f(p);
    std::string s;
    std::getline(f, s);
    return f ? s : std::string();
  };
  const std::string theirs = comm("/proc/" + std::to_string(pid) + "/comm"), ours = comm("/proc/self/comm");
  return theirs.empty() || ours.empty() || theirs == ours;
}

}  // namespace

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// One file on its way: written under a temporary, then named. Its members are set in that order
// and undone by discard().
struct WriteBatch::Prepared {
  std::string path;    // as given: messages name it
  std::string target;  // the file replaced (resolved_destination)
  std::string kind;    // "EXR", "PNG"
  int fd = -1;         // the unnamed O_TMPFILE inode, until it has a name
  std::string temp;    // the named temporary ("" while there is none)
  int slot = -1;       // temp's entry in the signal handler's table

  [[noreturn]] void fail(const std::string& why) const {
    throw Error(path + ": cannot write " + kind + ": " + one_line(why));
  }
  void name_temporary(std::string name) {
    temp = std::move(name);
    slot = register_temporary(temp);
  }
  void forget_temporary() {
    unregister_temporary(slot);
    temp.clear();
  }
  // Removes whatever exists of the file (never throws).
  void discard() noexcept {
    if (fd >= 0) ::close(fd);  // an unnamed file vanishes with its descriptor
    fd = -1;
    if (!temp.empty()) ::unlink(temp.c_str());
    forget_temporary();
  }
  ~Prepared() { discard(); }
};

namespace {

thread_local WriteBatch* t_batch = nullptr;

// Gives the file being written the permission bits and group (and, for root, the owner) of the
// regular file it will replace; a new file keeps the creation mode (0666 less the umask).
void keep_mode_and_group(int fd, const std::string& target) {
  struct stat st {};
  if (::stat(target.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return;
  // The group may be refused (not a member of it, root squashed on NFS): the file then has the
  // writer's group, as any rewrite by another user does. Not the permission bits: a private
  // (0600) output must not become readable by others.
  [[maybe_unused]] const int refused = ::fchown(fd, ::geteuid() == 0 ? st.st_uid : uid_t(-1), st.st_gid);
  if (::fchmod(fd, st.st_mode & 07777) != 0)
    throw Error(std::string("cannot give the new file the mode of the one it replaces: ") + error_text(errno));
}

// Writes the whole file into a temporary (p.fd unnamed, or p.temp closed), flushed: only the
// naming is left.
void prepare_file(WriteBatch::Prepared& p, const std::function<void(std::ostream& out, const std::string& name)>& body) {
  try {
    if (const std::string problem = destination_problem(p.path); !problem.empty()) throw Error(problem);
    p.target = resolved_destination(p.path);
    const std::string dir = parent_dir(p.target);
    p.fd = open_unnamed(dir);
    if (p.fd < 0) {
      p.name_temporary(temp_name(p.target));
      p.fd = ::open(p.temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      if (p.fd < 0) {
        const int err = errno;
        const std::string temp = p.temp;
        p.forget_temporary();  // nothing was created
        const std::string problem = destination_problem(p.path);  // a folder removed meanwhile
        throw Error(!problem.empty() ? problem
                                     : "cannot create temporary file '" + temp + "': " + error_text(err));
      }
    }
    keep_mode_and_group(p.fd, p.target);
    {
      FdBuf buffer(p.fd);
      std::ostream out(&buffer);
      body(out, p.temp.empty() ? p.path : p.temp);
      out.flush();  // a full disk shows up here
      if (!out || buffer.error() != 0)
        throw Error((p.temp.empty() ? std::string("writing the file") : "writing temporary file '" + p.temp + "'") +
                    " failed: " + error_text(buffer.error()));
    }
    if (!p.temp.empty()) {
      const int fd = p.fd;
      p.fd = -1;
      if (::close(fd) != 0) throw Error("closing temporary file '" + p.temp + "' failed: " + error_text(errno));
    }
  } catch (const std::bad_alloc&) {
    p.discard();
    p.fail("out of memory");
  } catch (const std::exception& e) {
    p.discard();
    p.fail(e.what());
  } catch (...) {
    p.discard();
    p.fail("unknown error");
  }
}

// Gives a prepared file its name: the target appears complete, replacing what was there.
void commit_file(WriteBatch::Prepared& p) {
  try {
    if (p.temp.empty()) {
      // Unnamed: a new target gets its name in one step; an existing one is replaced by a rename
      // from a named temporary (linkat does not replace), the only moment a kill -9 can leave a
      // (complete) temporary behind for the sweep.
      if (!link_unnamed(p.fd, p.target)) {
        if (errno != EEXIST) throw Error("cannot give the written file its name: " + error_text(errno));
        p.name_temporary(temp_name(p.target));
        if (!link_unnamed(p.fd, p.temp)) {
          const int err = errno;
          p.forget_temporary();
          throw Error("cannot give the written file a temporary name: " + error_text(err));
        }
        if (::rename(p.temp.c_str(), p.target.c_str()) != 0)
          throw Error("cannot rename '" + p.temp + "' onto the file: " + error_text(errno));
        p.forget_temporary();
      }
      const int fd = p.fd;
      p.fd = -1;
      if (::close(fd) != 0) throw Error("closing the file failed: " + error_text(errno));
    } else {
      if (::rename(p.temp.c_str(), p.target.c_str()) != 0)
        throw Error("cannot rename '" + p.temp + "' onto the file: " + error_text(errno));
      p.forget_temporary();
    }
  } catch (const std::exception& e) {
    p.discard();
    p.fail(e.what());
  }
}

}  // namespace

WriteBatch::WriteBatch() {
  if (t_batch != nullptr) throw Error("internal: a WriteBatch is already open on this thread");
  t_batch = this;
}

WriteBatch::~WriteBatch() {
  if (t_batch == this) t_batch = nullptr;
  prepared_.clear();  // removes what was not committed
}

void WriteBatch::commit() {
  if (t_batch == this) t_batch = nullptr;
  std::vector<std::unique_ptr<Prepared>> files = std::move(prepared_);
  prepared_.clear();
  for (auto& p : files) commit_file(*p);  // a failure throws; ~Prepared removes the rest
}

void write_file_atomically(const std::string& path, const char* kind,
                           const std::function<void(std::ostream& out, const std::string& name)>& body) {
  auto p = std::make_unique<WriteBatch::Prepared>();
  p->path = path;
  p->kind = kind;
  prepare_file(*p, body);
  if (t_batch != nullptr) {
    t_batch->prepared_.push_back(std::move(p));
    return;
  }
  commit_file(*p);
}

std::string destination_problem(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode) && ::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    std::error_code ec;
    const std::string to = std::filesystem::read_symlink(path, ec).string();
    if (err == ELOOP)
      return "it is a symbolic link to '" + to + "' in a loop of symbolic links (" + error_text(err) + ")";
    if (err != ENOENT) return "it is a symbolic link to '" + to + "', which cannot be followed (" + error_text(err) + ")";
    return "it is a symbolic link to '" + to + "', which does not exist";
  }
  if (::stat(path.c_str(), &st) == 0)
    return S_ISREG(st.st_mode) ? std::string() : std::string("it is ") + file_type_name(st.st_mode) +
                                                     ", not a regular file (fogcl replaces regular files only)";
  const int err = errno;
  if (err != ENOENT && err != ENOTDIR) return error_text(err);
  const std::string dir = parent_dir(path);
  if (::stat(dir.c_str(), &st) != 0)
    return errno == ENOENT ? "the folder '" + dir + "' does not exist" : "the folder '" + dir + "': " + error_text(errno);
  if (!S_ISDIR(st.st_mode)) return "'" + dir + "' is not a folder";
  return "";
}

std::string non_regular_kind(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode)) return "";
  return file_type_name(st.st_mode);
}

std::string resolved_destination(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return path;
  std::error_code ec;
  const std::filesystem::path resolved = std::filesystem::canonical(path, ec);
  return ec ? path : resolved.string();
}

std::string temporary_key(const std::string& name) {
  if (name.size() <= kKeyMax) return name;
  char hash[kHashDigits + 1];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(fnv1a64(name)));
  return name.substr(0, kKeyHead) + "~" + hash;
}

bool is_shortened_temporary_key(const std::string& key, std::string* head) {
  if (key.size() != kKeyMax || key[kKeyHead] != '~') return false;
  for (std::size_t i = kKeyHead + 1; i < key.size(); ++i)
    if (!std::isxdigit(static_cast<unsigned char>(key[i]))) return false;
  if (head != nullptr) *head = key.substr(0, kKeyHead);
  return true;
}

void remove_temporaries_now() noexcept {
  for (TempSlot& slot : g_slots)
    if (slot.state.load() == 2) ::unlink(slot.name);
}

void remove_temporaries_on_signals() {
  struct sigaction action {};
  action.sa_handler = remove_temporaries_and_die;
  sigemptyset(&action.sa_mask);
  for (int signo : {SIGINT, SIGTERM, SIGHUP}) sigaction(signo, &action, nullptr);
}

int remove_stale_temporaries(const std::string& dir, const std::function<bool(const std::string&)>& ours) {
  namespace fs = std::filesystem;
  const auto digits = [](const std::string& s) {
    return !s.empty() && s.size() <= 18 && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  int removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const std::size_t at = name.rfind(".tmp-");
    if (at == std::string::npos || at == 0) continue;
    // TARGET.tmp-HOST-PID-N, split from the right: HOST may contain '-'.
    const std::string rest = name.substr(at + 5);
    const std::size_t n_dash = rest.rfind('-');
    if (n_dash == std::string::npos || n_dash == 0) continue;
    const std::size_t pid_dash = rest.rfind('-', n_dash - 1);
    if (pid_dash == std::string::npos) continue;
    const std::string host = rest.substr(0, pid_dash), pid = rest.substr(pid_dash + 1, n_dash - pid_dash - 1);
    if (host != host_tag() || !digits(pid) || !digits(rest.substr(n_dash + 1))) continue;
    if (!ours(name.substr(0, at)) || may_be_running_fogcl(std::stol(pid))) continue;
    std::error_code ignored;
    if (fs::remove(it->path(), ignored)) ++removed;
  }
  return removed;
}

int remove_stale_temporaries_of(const std::vector<std::string>& paths) {
  int removed = 0;
  for (const std::string& path : paths) {
    if (path.empty()) continue;
    const std::filesystem::path target(resolved_destination(path));
    const std::string key = temporary_key(target.filename().string());
    removed += remove_stale_temporaries(parent_dir(target.string()), [&](const std::string& k) { return k == key; });
  }
  return removed;
}

std::string temporary_file_kind(const std::string& dir) {
  const int fd = open_unnamed(dir);
  if (fd < 0) return "named (TARGET.tmp-HOST-PID-N, swept by the next run if a kill leaves one)";
  ::close(fd);
  return "unnamed (O_TMPFILE: nothing is left if the process is killed)";
}

}  // namespace detail

}  // namespace fogcl
