#include "cli/sequence.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "fogcl/error.h"

namespace fogcl::cli {

namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// printf's escape: each "%%" from `from` on (the file name) names one '%' (the placeholder scan has
// checked that no other '%' is there).
std::string unescape_percent(const std::string& s, std::size_t from) {
  std::string out = s.substr(0, std::min(from, s.size()));
  for (std::size_t i = out.size(); i < s.size(); ++i) {
    out += s[i];
    if (s[i] == '%' && i + 1 < s.size() && s[i + 1] == '%') ++i;
  }
  return out;
}

std::size_t file_name_start(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? 0 : slash + 1;
}

}  // namespace

FramePattern parse_frame_pattern(const std::string& path) {
  FramePattern p;
  p.text = path;
  // Placeholders are looked for in the file name only: folders may contain '#' or '%'.
  const std::size_t name_start = path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1;
  std::size_t found_at = std::string::npos, found_len = 0;
  int width = 0, count = 0;
  for (std::size_t i = name_start; i < path.size();) {
    if (path[i] == '#') {
      std::size_t j = i;
      while (j < path.size() && path[j] == '#') ++j;
      found_at = i, found_len = j - i, width = int(j - i), ++count;
      i = j;
    } else if (path[i] == '%') {
      std::size_t j = i + 1;
      if (j < path.size() && path[j] == '%') {  // a literal '%'
        i = j + 1;
        continue;
      }
      bool zero = false;
      if (j < path.size() && path[j] == '0') zero = true, ++j;
      int w = 0;
      while (j < path.size() && is_digit(path[j]) && w < 100) w = w * 10 + (path[j++] - '0');
      if (j >= path.size() || path[j] != 'd' || (w > 0 && !zero) || w > 32)
        throw Error("'" + path + "': unsupported frame placeholder at '" + path.substr(i, std::min<std::size_t>(6, path.size() - i)) +
                    "' (use %d, %0Nd or a run of '#')");
      found_at = i, found_len = j + 1 - i, width = w == 0 ? 1 : w, ++count;
      i = j + 1;
    } else {
      ++i;
    }
  }
  if (count > 1) throw Error("'" + path + "': more than one frame placeholder in the file name");
  if (count == 0) return p;
  p.is_sequence = true;
  p.width = width;
  p.prefix = unescape_percent(path.substr(0, found_at), name_start);
  p.suffix = unescape_percent(path.substr(found_at + found_len), 0);
  return p;
}

std::string frame_path(const FramePattern& p, int frame) {
  if (!p.is_sequence) return unescape_percent(p.text, file_name_start(p.text));
  std::string digits = std::to_string(frame);
  if (int(digits.size()) < p.width) digits.insert(0, std::size_t(p.width) - digits.size(), '0');
  return p.prefix + digits + p.suffix;
}

std::vector<int> frames_on_disk(const FramePattern& p) {
  namespace fs = std::filesystem;
  std::vector<int> frames;
  if (!p.is_sequence) return frames;
  // "out/shot." -> folder "out", name stem "shot."; a trailing "x" keeps "out/" from being a folder
  // name with an empty file name.
  const fs::path probe(p.prefix + "x");
  const fs::path dir = probe.parent_path().empty() ? fs::path(".") : probe.parent_path();
  std::string stem = probe.filename().string();
  stem.pop_back();
  std::error_code ec;
  const auto cannot_list = [&] {
    return Error("'" + p.text + "': cannot list the folder '" + dir.string() + "' to find its frames: " + ec.message());
  };
  fs::directory_iterator it(dir, ec), end;
  if (ec) {
    if (ec == std::errc::no_such_file_or_directory || ec == std::errc::not_a_directory) return frames;
    throw cannot_list();
  }
  for (; it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= stem.size() + p.suffix.size() || name.compare(0, stem.size(), stem) != 0 ||
        name.compare(name.size() - p.suffix.size(), p.suffix.size(), p.suffix) != 0)
      continue;
    const std::string digits = name.substr(stem.size(), name.size() - stem.size() - p.suffix.size());
    if (digits.empty() || digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), is_digit)) continue;
    const int frame = std::stoi(digits);
    if (fs::path(frame_path(p, frame)).filename().string() == name) frames.push_back(frame);
  }
  if (ec) throw cannot_list();
  std::sort(frames.begin(), frames.end());
  return frames;
}

FrameRange parse_frame_range(const std::string& text) {
  const auto bad = [&] {
    return Error("--frames must be FRAME or FIRST-LAST with 0 <= FIRST <= LAST < 10^9 (got '" + text + "')");
  };
  const std::size_t dash = text.find('-');
  const std::string a = text.substr(0, dash), b = dash == std::string::npos ? a : text.substr(dash + 1);
  for (const std::string& s : {a, b})
    if (s.empty() || s.size() > 9 || !std::all_of(s.begin(), s.end(), is_digit)) throw bad();
  const int first = std::stoi(a), last = std::stoi(b);
  if (first > last) throw bad();
  return FrameRange{first, last};
}

SequenceFrames find_sequence_frames(const FramePattern& pattern, const std::optional<FrameRange>& wanted) {
  SequenceFrames out;
  std::vector<int> on_disk = frames_on_disk(pattern);
  if (wanted) {
    for (int f : on_disk)
      if (f >= wanted->first && f <= wanted->last) out.present.push_back(f);
  } else {
    out.present = std::move(on_disk);
  }
  const FrameRange span = wanted                  ? *wanted
                          : out.present.empty()   ? FrameRange{}
                                                  : FrameRange{out.present.front(), out.present.back()};
  out.requested = span.count();
  // The holes of `span` around the present frames (ascending, so one pass).
  long long next = span.first;  // the first frame not yet accounted for
  const auto hole_until = [&](long long end) {  // frames next..end-1 are missing
    if (end > next) {
      out.missing.push_back({int(next), int(end - 1)});
      out.missing_count += end - next;
    }
  };
  for (int f : out.present) {
    hole_until(f);
    next = (long long)f + 1;
  }
  if (span.count() > 0) hole_until((long long)span.last + 1);
  return out;
}

std::string ranges_text(const std::vector<FrameRange>& ranges, std::size_t max_ranges) {
  std::string out;
  for (std::size_t i = 0; i < ranges.size() && i < max_ranges; ++i) {
    const FrameRange& r = ranges[i];
    out += (i > 0 ? ", " : "") + std::to_string(r.first) + (r.last > r.first ? "-" + std::to_string(r.last) : "");
  }
  if (ranges.size() > max_ranges) out += ", ... (" + std::to_string(ranges.size() - max_ranges) + " more ranges)";
  return out;
}

ProgressBar::ProgressBar(int total, bool enabled)
    : total_(total), enabled_(enabled && ::isatty(STDERR_FILENO) == 1), start_(std::chrono::steady_clock::now()) {}

std::string progress_text(int done, int total, double first_done_s, double last_done_s) {
  const int width = 30;
  const int filled = total > 0 ? std::clamp(int(double(width) * done / total), 0, width) : width;
  std::string bar(std::size_t(filled), '=');
  bar.resize(std::size_t(width), ' ');
  double rate = 0;
  if (done >= 2 && last_done_s > first_done_s)
    rate = (done - 1) / (last_done_s - first_done_s);
  else if (done >= 1 && last_done_s > 0)
    rate = done / last_done_s;
  char buf[160];
  int n = std::snprintf(buf, sizeof buf, "[%s] %d/%d frames  %.2f frames/s", bar.c_str(), done, total, rate);
  if (rate > 0 && done < total) {
    const long eta = std::lround((total - done) / rate);
    std::snprintf(buf + n, sizeof buf - std::size_t(n), "  ETA %ld:%02ld", eta / 60, eta % 60);
  }
  return buf;
}

void ProgressBar::update(int done) {
  if (!enabled_) return;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (done >= 1 && first_done_s_ < 0) first_done_s_ = seconds;
  std::fprintf(stderr, "\r%s\033[K", progress_text(done, total_, first_done_s_, seconds).c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::clear() {
  if (!enabled_ || !drawn_) return;
  std::fprintf(stderr, "\r\033[K");
  drawn_ = false;
}

void ProgressBar::finish() {
  if (!enabled_ || !drawn_) return;
  std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace fogcl::cli
