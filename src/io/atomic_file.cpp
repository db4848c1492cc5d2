#include "io/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <exception>
#include <filesystem>
#include <new>
#include <system_error>

#include "fogcl/error.h"

namespace fogcl {

namespace detail {

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

void write_file_atomically(const std::string& path, const char* kind,
                           const std::function<void(std::ofstream& out, const std::string& temp_path)>& body) {
  // Unique per process (pid) and per call (counter): concurrent writers never share a temp file.
  static std::atomic<unsigned long> counter{0};
  const std::string temp_path =
      path + ".tmp-" + std::to_string(long(::getpid())) + "-" + std::to_string(counter++);
  try {
    {
      std::ofstream out(temp_path, std::ios::binary | std::ios::trunc);
      if (!out) throw Error("cannot create temporary file '" + temp_path + "': " + std::strerror(errno));
      body(out, temp_path);
      out.close();  // flushes: a full disk shows up here
      if (out.fail()) throw Error("writing temporary file '" + temp_path + "' failed: " + std::strerror(errno));
    }
    std::filesystem::rename(temp_path, path);
  } catch (const std::exception& e) {
    std::error_code ignored;
    std::filesystem::remove(temp_path, ignored);
    if (dynamic_cast<const std::bad_alloc*>(&e) != nullptr)
      throw Error(path + ": cannot write " + kind + ": out of memory");
    throw Error(path + ": cannot write " + kind + ": " + one_line(e.what()));
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temp_path, ignored);
    throw Error(path + ": cannot write " + kind + ": unknown error");
  }
}

}  // namespace detail

}  // namespace fogcl
