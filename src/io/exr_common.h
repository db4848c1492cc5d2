// Helpers shared by the EXR reader and writer (src/io only).
#pragma once

#include <cstdint>
#include <exception>
#include <new>
#include <string>

#include <cerrno>
#include <cstring>
#include <ostream>

#include <Iex.h>
#include <Imath/ImathBox.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfIO.h>

#include "fogcl/error.h"
#include "fogcl/exr_io.h"
#include "io/atomic_file.h"

namespace fogcl::detail {

inline std::string box_string(const Imath::Box2i& b) {
  return "(" + std::to_string(b.min.x) + ", " + std::to_string(b.min.y) + ")-(" + std::to_string(b.max.x) +
         ", " + std::to_string(b.max.y) + ")";
}

inline Imath::Box2i to_box(const glm::ivec2& min, const glm::ivec2& max) {
  return Imath::Box2i(Imath::V2i(min.x, min.y), Imath::V2i(max.x, max.y));
}

inline std::string box_string(const glm::ivec2& min, const glm::ivec2& max) { return box_string(to_box(min, max)); }

inline ExrWindows to_windows(const Imath::Box2i& display, const Imath::Box2i& data) {
  ExrWindows w;
  w.display_min = {display.min.x, display.min.y};
  w.display_max = {display.max.x, display.max.y};
  w.data_min = {data.min.x, data.min.y};
  w.data_max = {data.max.x, data.max.y};
  return w;
}

inline std::string channel_names(const Imf::ChannelList& channels) {
  std::string names;
  for (auto it = channels.begin(); it != channels.end(); ++it) {
    if (!names.empty()) names += ", ";
    names += it.name();
  }
  return names.empty() ? std::string("none") : names;
}

inline bool inside(const Imath::Box2i& inner, const Imath::Box2i& outer) {
  return inner.min.x >= outer.min.x && inner.min.y >= outer.min.y && inner.max.x <= outer.max.x &&
         inner.max.y <= outer.max.y;
}

// Size of an inclusive box along one axis, in 64 bits (max - min overflows int for huge boxes).
inline std::int64_t extent(int min, int max) { return std::int64_t(max) - std::int64_t(min) + 1; }

// OpenEXR's output stream over the std::ostream that write_file_atomically hands out (Imf's own
// StdOFStream wants an std::ofstream, which cannot hold an unnamed O_TMPFILE file).
class OStreamAdapter : public Imf::OStream {
 public:
  OStreamAdapter(std::ostream& out, const std::string& name) : Imf::OStream(name.c_str()), out_(out) {}
  void write(const char c[], int n) override {
    if (!out_.write(c, n)) throw Iex::IoExc(std::string("write failed: ") + std::strerror(errno != 0 ? errno : EIO));
  }
  std::uint64_t tellp() override { return std::uint64_t(std::streamoff(out_.tellp())); }
  void seekp(std::uint64_t pos) override {
    if (!out_.seekp(std::streamoff(pos))) throw Iex::IoExc(std::string("seek failed: ") + std::strerror(errno != 0 ? errno : EIO));
  }

 private:
  std::ostream& out_;
};

// Runs `read` and turns whatever OpenEXR (Iex), the standard library or the allocator throws into
// one fogcl::Error line naming the file. Our own fogcl::Errors already name it and pass through.
template <class Read>
auto with_read_errors(const std::string& path, Read&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw OutOfMemory(path + ": cannot read EXR: out of memory");
  } catch (const std::exception& e) {  // Iex::BaseExc derives from std::exception
    throw Error(path + ": cannot read EXR: " + one_line(e.what()));
  } catch (...) {
    throw Error(path + ": cannot read EXR: unknown error");
  }
}

}  // namespace fogcl::detail
