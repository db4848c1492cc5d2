#include "io/exr_precheck.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "fogcl/error.h"
#include "fogcl/exr_io.h"

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

// The most bytes of pixels one stored byte can decode to, per compression: a header whose pixels
// could not fit in the file even so is refused before anything is allocated for them. Upper bounds
// of each decoder, with margin (the OpenEXR file layout; ImfRle.cpp, ImfHuf.cpp, ImfDwaCompressor.cpp):
//   NONE   1      the pixels as they are
//   RLE    64     a run of up to 128 equal bytes in 2
//   ZIPS,  1032   deflate's limit: a 258-byte match in 2 bits (zlib's FAQ)
//   ZIP
//   PIZ    512    Huffman with run codes: up to 255 repeats of a 16-bit value in 9 bits (453)
//   PXR24  1376   deflate of floats cut to 24 bits: 1032 * 4 / 3
//   B44,   32/3   a flat 4x4 block of half values (32 bytes) in 3; other types are stored raw
//   B44A
//   DWAA,  66048  one DC value per 8x8 block, deflated: 64 * 1032 (the other streams expand less)
//   DWAB
// 0 = unknown (no bound; OpenEXR refuses a compression it does not know).
double max_expansion(int compression) {
  switch (compression) {
    case 0: return 1;
    case 1: return 64;
    case 2: case 3: return 1032;
    case 4: return 512;
    case 5: return 1376;
    case 6: case 7: return 32.0 / 3.0;
    case 8: case 9: return 66048;
    default: return 0;
  }
}

std::string bytes_text(double bytes) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.0f", bytes);
  return buf;
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
  // The least the file must hold after its headers and offset tables: each part's chunk headers
  // and its pixels as compressed as its compression could make them (max_expansion).
  double least_bytes = 0;
  std::string largest_claim;  // the part whose pixels need the most bytes, for the message
  double largest_least = -1;
  for (int part = 0;; ++part) {
    bool tiled = tiled_single, deep = false, have_data = false;
    std::int64_t data_w = 0, data_h = 0, chunk_count = -1;
    std::int32_t data_box[4] = {0, 0, -1, -1};
    int compression = 0, tile_w = 0, tile_h = 0;
    struct ChannelSize {
      int bytes, x_sampling, y_sampling;
    };
    std::vector<ChannelSize> channels;
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
        // Each channel: pixel type (0 UINT, 1 HALF, 2 FLOAT), pLinear, 3 reserved bytes, x and y sampling.
        std::string channel;
        char fields[16];
        for (;;) {
          read_name(channel);
          if (channel.empty()) break;
          get(16, fields);
          const std::int32_t pixel_type = le32(fields);
          if (attr == "channels")
            channels.push_back({pixel_type == 1 ? 2 : pixel_type == 0 || pixel_type == 2 ? 4 : 0, le32(fields + 8),
                                le32(fields + 12)});
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
        if (attr == "dataWindow") {
          have_data = w > 0 && h > 0, data_w = w, data_h = h;
          for (int i = 0; i < 4; ++i) data_box[i] = le32(&value[std::size_t(4 * i)]);
        }
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
        deep = t == "deepscanline" || t == "deeptile";
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
    // Level 0's pixels (a deep part: its sample count table, 4 bytes a pixel; it may hold no samples).
    double pixel_bytes = 0;
    if (have_data) {
      if (deep) {
        pixel_bytes = 4.0 * double(data_w) * double(data_h);
      } else {
        for (const ChannelSize& c : channels)
          if (c.x_sampling > 0 && c.y_sampling > 0)
            pixel_bytes += double(c.bytes) * double(data_w / c.x_sampling) * double(data_h / c.y_sampling);
      }
    }
    // A chunk starts with its coordinates and sizes: y and size (scan lines), 4 tile coordinates
    // and size (tiles); deep chunks state three 8-byte sizes instead of one; and a part number in
    // multi-part files.
    const int chunk_header = (tiled ? 16 : 4) + (deep ? 24 : 4) + (multipart ? 4 : 0);
    const double expansion = max_expansion(compression);
    const double least = double(chunks) * chunk_header + (expansion > 0 ? pixel_bytes / expansion : 0.0);
    least_bytes += least;
    if (least > largest_least) {
      largest_least = least;
      largest_claim = std::string(multipart ? "part " + std::to_string(part) + ": " : "") + "dataWindow (" +
                      std::to_string(data_box[0]) + ", " + std::to_string(data_box[1]) + ")-(" +
                      std::to_string(data_box[2]) + ", " + std::to_string(data_box[3]) + ") holds " +
                      bytes_text(pixel_bytes) + " bytes of " + (deep ? "deep sample counts" : "pixels") + "; " +
                      exr_compression_name(compression) + " compression and " + std::to_string(chunks) +
                      " chunks store that in no fewer than " + bytes_text(std::ceil(least)) + " bytes";
    }
    if (multipart) {
      char next = 0;
      get(1, &next);  // an empty name ends the header list
      if (next != 0) {
        --pos;
        continue;
      }
    }
    break;
  }
  // pos is the end of the headers; the offset tables (8 bytes a chunk) follow, then the chunks.
  const double after_headers = double(file_size - pos) - 8.0 * double(chunks_total);
  if (least_bytes > after_headers)
    throw fail(largest_claim + ", but the file has " + bytes_text(after_headers) +
               " bytes after its headers and offset tables (truncated or corrupt)");
}

}  // namespace fogcl::detail
