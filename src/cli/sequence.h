// Frame sequences for `fogcl apply`: 'shot.####.exr' or 'shot.%04d.exr' names a frame range.
#pragma once

#include <chrono>
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
// The path of `frame` (>= 0); the pattern's text itself when it is not a sequence.
std::string frame_path(const FramePattern& pattern, int frame);
// Frames whose files exist, ascending (a name counts when frame_path() gives it back exactly).
std::vector<int> frames_on_disk(const FramePattern& pattern);
// "12" or "1-48" (inclusive, first <= last, both >= 0); throws fogcl::Error naming the text.
std::vector<int> parse_frame_range(const std::string& text);

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
