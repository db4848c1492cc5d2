// Frame sequences for `fogcl apply`: 'shot.####.exr' or 'shot.%04d.exr' names a frame range.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace fogcl::cli {

// A path with at most one frame number placeholder: a run of '#' (its length is the zero-padded
// width) or printf's %d / %0Nd. Paths without one are single files.
struct FramePattern {
  std::string prefix, suffix;
  int width = 0;             // minimum digits (zero-padded); frames with more digits print them all
  bool is_sequence = false;
  std::string text;          // as given
};

// Throws fogcl::Error for two placeholders or an unsupported printf conversion ("%5d", "%s").
FramePattern parse_frame_pattern(const std::string& path);
// The path of `frame` (>= 0); the pattern's text itself when it is not a sequence. In both, "%%"
// is a literal '%' (printf's escape; folders keep theirs: placeholders are only looked for in the
// file name, so is the escape).
std::string frame_path(const FramePattern& pattern, int frame);
// Frames whose files exist, ascending (a name counts when frame_path() gives it back exactly).
// A folder that does not exist has none; one that cannot be listed throws fogcl::Error.
std::vector<int> frames_on_disk(const FramePattern& pattern);

// Frames first..last, inclusive.
struct FrameRange {
  int first = 0, last = -1;
  long long count() const { return last < first ? 0 : (long long)last - first + 1; }
};
// "12" or "1-48" (inclusive, 0 <= first <= last < 10^9); throws fogcl::Error naming the text.
FrameRange parse_frame_range(const std::string& text);

// The frames of a sequence: those whose files exist within `wanted` (--frames), and the rest of
// `wanted` as missing ranges; without `wanted`, the frames on disk and the gaps between the first
// and the last of them. One listing of the folder: nothing is spent per absent frame, however
// large the range (--frames 1-999999999 costs what the folder's files cost).
struct SequenceFrames {
  std::vector<int> present;         // ascending
  std::vector<FrameRange> missing;  // ascending, disjoint, not adjacent
  long long missing_count = 0;      // frames in `missing`
  long long requested = 0;          // present + missing
};
SequenceFrames find_sequence_frames(const FramePattern& pattern, const std::optional<FrameRange>& wanted);

// "3, 7-9, 1001-999999999": at most `max_ranges` ranges, then ", ... (N more ranges)", so that a
// sequence with every other frame missing still gives one short line.
std::string ranges_text(const std::vector<FrameRange>& ranges, std::size_t max_ranges = 8);

// The text of the progress bar: "[=====     ] 12/48 frames  3.10 frames/s  ETA 0:12". With frames
// in flight the first frame finishes after a whole pipeline's latency and the next ones one
// throughput apart, so the rate is taken between finished frames: (done - 1) / (last - first), the
// time of the first and the latest finish since the start [s]; with one frame done, done / last.
// ETA = frames left / rate.
std::string progress_text(int done, int total, double first_done_s, double last_done_s);

// A one-line progress bar (progress_text) on stderr, drawn only when stderr is a terminal.
class ProgressBar {
 public:
  ProgressBar(int total, bool enabled);
  void update(int done);
  // Erases the bar (before printing a message line); the next update() draws it again.
  void clear();
  void finish();
  bool enabled() const { return enabled_; }

 private:
  int total_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
  double first_done_s_ = -1;
};

}  // namespace fogcl::cli
