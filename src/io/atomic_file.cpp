#include "io/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
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
    for (char& c : s)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-')) c = '_';
    return s;
  }();
  return tag;
}

std::string temp_name(const std::string& path) {
  // Unique per machine (host), process (pid) and call (counter): concurrent writers never share one.
  static std::atomic<unsigned long> counter{0};
  return path + ".tmp-" + host_tag() + "-" + std::to_string(long(::getpid())) + "-" + std::to_string(counter++);
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

void write_file_atomically(const std::string& path, const char* kind,
                           const std::function<void(std::ostream& out, const std::string& name)>& body) {
  int fd = -1;
  std::string temp;  // the named temporary, "" while the file has no name
  const auto close_fd = [&] {
    const int result = fd >= 0 ? ::close(fd) : 0;
    fd = -1;
    return result == 0;
  };
  try {
    fd = open_unnamed(parent_dir(path));
    if (fd < 0) {
      temp = temp_name(path);
      fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      if (fd < 0) {
        const int err = errno;
        temp.clear();  // nothing was created
        throw Error("cannot create temporary file '" + temp_name(path) + "': " + error_text(err));
      }
    }
    {
      FdBuf buffer(fd);
      std::ostream out(&buffer);
      body(out, temp.empty() ? path : temp);
      out.flush();  // a full disk shows up here
      if (!out || buffer.error() != 0)
        throw Error((temp.empty() ? std::string("writing the file") : "writing temporary file '" + temp + "'") +
                    " failed: " + error_text(buffer.error()));
    }
    if (temp.empty()) {
      // Complete: name it. A new target gets its name in one step; an existing one is replaced by
      // a rename from a named temporary (linkat does not replace), the only moment a kill can
      // leave a (complete) temporary behind for the sweep.
      if (!link_unnamed(fd, path)) {
        if (errno != EEXIST) throw Error("cannot give the written file its name: " + error_text(errno));
        temp = temp_name(path);
        if (!link_unnamed(fd, temp)) {
          const int err = errno;
          temp.clear();
          throw Error("cannot give the written file a temporary name: " + error_text(err));
        }
        std::filesystem::rename(temp, path);
      }
      if (!close_fd()) throw Error("closing the file failed: " + error_text(errno));
    } else {
      if (!close_fd()) throw Error("closing temporary file '" + temp + "' failed: " + error_text(errno));
      std::filesystem::rename(temp, path);
    }
  } catch (const std::exception& e) {
    close_fd();
    if (!temp.empty()) ::unlink(temp.c_str());  // an unnamed file vanishes with its descriptor
    if (dynamic_cast<const std::bad_alloc*>(&e) != nullptr)
      throw Error(path + ": cannot write " + kind + ": out of memory");
    throw Error(path + ": cannot write " + kind + ": " + one_line(e.what()));
  } catch (...) {
    close_fd();
    if (!temp.empty()) ::unlink(temp.c_str());
    throw Error(path + ": cannot write " + kind + ": unknown error");
  }
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

std::string temporary_file_kind(const std::string& dir) {
  const int fd = open_unnamed(dir);
  if (fd < 0) return "named (TARGET.tmp-HOST-PID-N, swept by the next run if a kill leaves one)";
  ::close(fd);
  return "unnamed (O_TMPFILE: nothing is left if the process is killed)";
}

}  // namespace detail

}  // namespace fogcl
