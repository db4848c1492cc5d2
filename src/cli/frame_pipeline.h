// The bounded pipeline of `fogcl apply` on a sequence: frame N+1 is read while frame N is fogged
// and frame N-1 is written. One thread per stage, so each stage sees the frames in order and the
// outputs appear in order; a stage waits when the next one is a frame behind, so at most five
// frames are alive at once (one per stage, one waiting between each two). The heavy work inside
// the read and write stages ((de)compression) runs on OpenEXR's thread pool, shared by both. The
// caller's thread is left for set-up that must run there (Stages::start) while frames flow. With
// one core the stages run in turn on the caller's thread instead (run(..., serial)).
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace fogcl::cli {

// Job: one frame's work in flight; must have `int frame` and `std::string error` ("" = fine).
// Clock: what the stages' busy times are measured with (a test gives a clock of its own).
template <class Job, class Clock = std::chrono::steady_clock>
class FramePipeline {
 public:
  using Stage = std::function<void(Job&)>;
  struct Stages {
    Stage read;   // reader thread: loads the frame's inputs
    Stage fog;    // fog thread: the passes (the device); skipped for a frame that failed to read
    Stage write;  // writer thread: writes the outputs; skipped for a failed frame
    // The caller's thread, once, after the stage threads have started (may be empty): set-up
    // that overlaps the frames' reading, fogging and writing. run() returns when it and the
    // frames are done. Must not throw.
    std::function<void()> start;
    // Writer thread, in frame order, after each frame: error "" or what failed. Returns false to
    // stop the run (frames not yet written are dropped).
    std::function<bool(const Job&)> done;
  };
  struct Outcome {
    int finished = 0;          // frames that reached done(), failed or not
    bool interrupted = false;  // *interrupt became non-zero before every frame finished
    // Wall seconds each stage spent working (waits excluded) and the whole run: the busiest
    // stage bounds the frame rate (--verbose prints them).
    double read_s = 0, fog_s = 0, write_s = 0, total_s = 0;
  };

  // Runs `frames` through the stages. A non-zero *interrupt (set by a signal handler) stops it:
  // the write in progress completes, nothing else starts. `serial`: start(), then each frame's
  // stages one after another on the caller's thread, for a process with one core, where nothing
  // can overlap and interleaving the stages only makes them evict each other's caches (a 4K PIZ
  // frame's decoder and encoder buffers are a megabyte or more each).
  static Outcome run(const std::vector<int>& frames, const Stages& stages, const std::atomic<int>* interrupt,
                     bool serial = false) {
    if (serial) return run_serial(frames, stages, interrupt);
    FramePipeline p(interrupt);
    Outcome outcome;
    const auto start = Clock::now();
    double read_s = 0, fog_s = 0;  // each written by its stage's thread, read after the join
    std::thread reader, fogger, writer;
    // Whatever way this function leaves, the stage threads are stopped and joined first.
    struct Joiner {
      FramePipeline& p;
      std::thread &a, &b, &c;
      void join() {
        p.stop();
        for (std::thread* t : {&a, &b, &c})
          if (t->joinable()) t->join();
      }
      ~Joiner() { join(); }
    } joiner{p, reader, fogger, writer};
    reader = std::thread([&] {
      for (int frame : frames) {
        if (p.stopped()) break;
        auto job = std::make_unique<Job>();
        job->frame = frame;
        read_s += timed(*job, stages.read);
        if (!p.read_to_fog_.push(std::move(job), p)) break;
      }
      p.read_to_fog_.close();
    });
    fogger = std::thread([&] {
      while (auto job = p.read_to_fog_.pop(p)) {
        if ((*job)->error.empty()) fog_s += timed(**job, stages.fog);
        if (!p.fog_to_write_.push(std::move(*job), p)) break;
      }
      p.fog_to_write_.close();
    });
    writer = std::thread([&] {
      while (auto job = p.fog_to_write_.pop(p)) {
        if (p.interrupted()) break;
        if ((*job)->error.empty()) outcome.write_s += timed(**job, stages.write);
        ++outcome.finished;
        if (!stages.done(**job)) break;
      }
      p.stop();  // done() stopped the run, or every frame is written: the other stages end too
    });
    if (stages.start) stages.start();
    writer.join();
    outcome.interrupted = p.interrupted() && outcome.finished < int(frames.size());
    joiner.join();
    outcome.read_s = read_s;
    outcome.fog_s = fog_s;
    outcome.total_s = std::chrono::duration<double>(Clock::now() - start).count();
    return outcome;
  }

 private:
  explicit FramePipeline(const std::atomic<int>* interrupt) : interrupt_(interrupt) {}

  static Outcome run_serial(const std::vector<int>& frames, const Stages& stages, const std::atomic<int>* interrupt) {
    FramePipeline p(interrupt);
    Outcome outcome;
    const auto start = Clock::now();
    if (stages.start) stages.start();
    for (int frame : frames) {
      if (p.interrupted()) break;
      Job job;
      job.frame = frame;
      outcome.read_s += timed(job, stages.read);
      if (p.interrupted()) break;  // as the threads: only a write in progress completes
      if (job.error.empty()) outcome.fog_s += timed(job, stages.fog);
      if (p.interrupted()) break;
      if (job.error.empty()) outcome.write_s += timed(job, stages.write);
      ++outcome.finished;
      if (!stages.done(job)) break;
    }
    outcome.interrupted = p.interrupted() && outcome.finished < int(frames.size());
    outcome.total_s = std::chrono::duration<double>(Clock::now() - start).count();
    return outcome;
  }

  bool interrupted() const { return interrupt_ != nullptr && interrupt_->load() != 0; }
  bool stopped() const { return stop_.load() || interrupted(); }
  void stop() {
    stop_ = true;
    read_to_fog_.wake();
    fog_to_write_.wake();
  }
  // Runs the stage (guarded); returns its wall seconds.
  static double timed(Job& job, const Stage& stage) {
    const auto t = Clock::now();
    guard(job, stage);
    return std::chrono::duration<double>(Clock::now() - t).count();
  }
  static void guard(Job& job, const Stage& stage) {
    try {
      stage(job);
    } catch (const std::exception& e) {
      job.error = e.what();
    } catch (...) {
      job.error = "unknown error";
    }
  }

  // One frame between two stages at most. Waits poll the interrupt flag: a signal handler cannot
  // notify a condition variable.
  class Slot {
   public:
    bool push(std::unique_ptr<Job> job, const FramePipeline& p) {
      std::unique_lock<std::mutex> lock(m_);
      while (!items_.empty() && !p.stopped()) cv_.wait_for(lock, std::chrono::milliseconds(50));
      if (p.stopped()) return false;
      items_.push_back(std::move(job));
      cv_.notify_all();
      return true;
    }
    std::optional<std::unique_ptr<Job>> pop(const FramePipeline& p) {
      std::unique_lock<std::mutex> lock(m_);
      while (items_.empty() && !closed_ && !p.stopped()) cv_.wait_for(lock, std::chrono::milliseconds(50));
      if (p.stopped() || items_.empty()) return std::nullopt;
      std::unique_ptr<Job> job = std::move(items_.front());
      items_.pop_front();
      cv_.notify_all();
      return job;
    }
    void close() {
      std::lock_guard<std::mutex> lock(m_);
      closed_ = true;
      cv_.notify_all();
    }
    void wake() {
      std::lock_guard<std::mutex> lock(m_);
      cv_.notify_all();
    }

   private:
    std::mutex m_;
    std::condition_variable cv_;
    std::deque<std::unique_ptr<Job>> items_;
    bool closed_ = false;
  };

  const std::atomic<int>* interrupt_;
  std::atomic<bool> stop_{false};
  Slot read_to_fog_, fog_to_write_;
};

}  // namespace fogcl::cli
