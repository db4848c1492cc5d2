#include "io/exr_precheck.h"

#include <cstring>
#include <vector>

#include "fogcl/error.h"

namespace fogcl::detail {

namespace {

std::int32_t le32(const char* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | std::uint8_t(p[i]);
  return std::int32_t(v);
}

// Scan lines per chunk of each compression (OpenEXR file layout, "Compression methods").
int lines_per_chunk(int compression) {
  switch (compression) {
    case 0: case 1: case 2: return 1;   // NONE, RLE, ZIPS
    case 3: case 5: return 16;          // ZIP, PXR24
    case 4: case 6: case 7: case 8: return 32;  // PIZ, B44, B44A, DWAA
    case 9: return 256;                 // DWAB
    default: return 1;
  }
}

// Value sizes of the fixed-size attribute types (OpenEXR file layout, "Attribute types"). OpenEXR
// 3.1 reads that many bytes whatever size the file states, so a different stated size means the
// two walks would part ways: such a file is corrupt.
int fixed_size(const std::string& type) {
  static const struct {
    const char* type;
    int size;
  } sizes[] = {{"box2i", 16},    {"box2f", 16},   {"compression", 1}, {"lineOrder", 1}, {"envmap", 1},
               {"deepImageState", 1}, {"float", 4}, {"int", 4},        {"double", 8},    {"rational", 8},
               {"timecode", 8},  {"v2i", 8},      {"v2f", 8},         {"v2d", 16},      {"v3i", 12},
               {"v3f", 12},      {"v3d", 24},     {"m33f", 36},       {"m33d", 72},     {"m44f", 64},
               {"m44d", 128},    {"tiledesc", 9}, {"chromaticities", 32}, {"keycode", 28}};
  for (const auto& s : sizes)
    if (type == s.type) return s.size;
  return -1;
}

}  // namespace

void precheck_exr_header(const std::string& name, std::uint64_t file_size, std::int64_t max_pixels,
                         const std::function<void(std::uint64_t, std::size_t, char*)>& read) {
  const auto fail = [&](const std::string& why) { return Error(name + ": cannot read EXR: " + why); };
  std::uint64_t pos = 0;
  const auto get = [&](std::size_t n, char* dst) {
    if (pos > file_size || n > file_size - pos) throw fail("unexpected end of file in the header");
    read(pos, n, dst);
    pos += n;
  };
  char head[8];
  get(8, head);
  if (le32(head) != 20000630) throw fail("not an OpenEXR file (wrong magic number)");
  const std::uint32_t flags = std::uint32_t(le32(head + 4));
  const bool multipart = (flags & 0x1000u) != 0, tiled_single = (flags & 0x200u) != 0;
  const std::size_t max_name = (flags & 0x400u) != 0 ? 256 : 32;
  const auto read_name = [&](std::string& out) {
    out.clear();
    char c = 0;
    for (;;) {
      get(1, &c);
      if (c == 0) return;
      if (out.size() >= max_name) throw fail("attribute name longer than " + std::to_string(max_name) + " bytes");
      out += c;
    }
  };
  std::uint64_t chunks_total = 0;
  for (int part = 0;; ++part) {
    bool tiled = tiled_single, have_data = false;
    std::int64_t data_w = 0, data_h = 0, chunk_count = -1;
    int compression = 0, tile_w = 0, tile_h = 0;
    std::string attr, type;
    for (;;) {
      read_name(attr);
      if (attr.empty()) break;
      read_name(type);
      char size_bytes[4];
      get(4, size_bytes);
      const std::int32_t size = le32(size_bytes);
      if (size < 0 || std::uint64_t(size) > file_size - pos)
        throw fail("attribute '" + attr + "' claims " + std::to_string(size) + " bytes, more than the rest of the file");
      const int fixed = fixed_size(type);
      if (fixed >= 0 && size != fixed)
        throw fail("attribute '" + attr + "' of type " + type + " states " + std::to_string(size) +
                   " bytes instead of " + std::to_string(fixed));
      if (type == "chlist") {
        // OpenEXR reads a channel list up to its empty name, whatever the stated size says, and
        // goes on from there: follow it the same way so both walks stay in step.
        std::string channel;
        char fields[16];
        for (;;) {
          read_name(channel);
          if (channel.empty()) break;
          get(16, fields);
        }
        continue;
      }
      if (type == "preview") {
        // width, height, then width * height RGBA bytes, allocated from the stated width x height.
        char wh[8];
        if (size < 8) throw fail("preview attribute of " + std::to_string(size) + " bytes");
        get(8, wh);
        const std::uint64_t pw = std::uint32_t(le32(wh)), ph = std::uint32_t(le32(wh + 4));
        if ((ph != 0 && pw > (std::uint64_t(size) - 8) / ph) || pw * ph * 4 != std::uint64_t(size) - 8)
          throw fail("preview attribute of " + std::to_string(pw) + "x" + std::to_string(ph) +
                     " pixels does not match its size of " + std::to_string(size) + " bytes");
        pos += std::uint64_t(size) - 8;
        continue;
      }
      std::vector<char> value;
      const bool wanted = (type == "box2i" && size == 16) || (type == "compression" && size == 1) ||
                          (type == "tiledesc" && size == 9) || (attr == "chunkCount" && size == 4) ||
                          (attr == "type" && size < 64);
      if (wanted) {
        value.resize(std::size_t(size));
        get(std::size_t(size), value.data());
      } else {
        pos += std::uint64_t(size);
      }
      if (type == "box2i" && size == 16) {
        const std::int64_t w = std::int64_t(le32(&value[8])) - le32(&value[0]) + 1;
        const std::int64_t h = std::int64_t(le32(&value[12])) - le32(&value[4]) + 1;
        if (w > 0 && h > 0 && w > max_pixels / h)  // w * h may not fit in 64 bits (found by the fuzzer)
          throw fail(attr + " is " + std::to_string(w) + "x" + std::to_string(h) + " pixels, more than the limit of " +
                     (max_pixels == (std::int64_t(1) << 31) ? std::string("2^31") : std::to_string(max_pixels)));
        if (attr == "dataWindow") have_data = w > 0 && h > 0, data_w = w, data_h = h;
      } else if (type == "compression" && size == 1) {
        compression = std::uint8_t(value[0]);
      } else if (type == "tiledesc" && size == 9) {
        tile_w = le32(&value[0]), tile_h = le32(&value[4]);
        // OpenEXR sizes its tile buffers from these before reading a tile.
        if (tile_w < 1 || tile_h < 1 || std::int64_t(tile_w) * tile_h > max_pixels)
          throw fail("tiles of " + std::to_string(tile_w) + "x" + std::to_string(tile_h) +
                     " pixels (at least 1x1, at most the pixel limit)");
      } else if (attr == "chunkCount" && size == 4) {
        chunk_count = le32(&value[0]);
      } else if (attr == "type" && size < 64) {
        const std::string t(value.begin(), value.end());
        tiled = t == "tiledimage" || t == "deeptile";
      }
    }
    // A lower bound of the chunks: the chunk count if stated, else level 0's chunks.
    std::uint64_t chunks = 0;
    if (chunk_count >= 0) {
      chunks = std::uint64_t(chunk_count);
    } else if (have_data) {
      if (tiled && tile_w > 0 && tile_h > 0)
        chunks = std::uint64_t((data_w + tile_w - 1) / tile_w) * std::uint64_t((data_h + tile_h - 1) / tile_h);
      else if (!tiled)
        chunks = std::uint64_t((data_h + lines_per_chunk(compression) - 1) / lines_per_chunk(compression));
    }
    chunks_total += chunks;
    if (chunks_total > file_size / 8)
      throw fail("the headers announce " + std::to_string(chunks_total) + " chunks, whose offset table alone is larger than the " +
                 std::to_string(file_size) + "-byte file (truncated or corrupt)");
    if (!multipart) return;
    char next = 0;
    get(1, &next);  // an empty name ends the header list
    if (next == 0) return;
    --pos;
  }
}

}  // namespace fogcl::detail
