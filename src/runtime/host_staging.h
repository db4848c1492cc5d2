// Host images to and from a device that is not the host's memory (a GPU): pinned staging at the
// speed of the bus (docs/gpu.md, "Host round trip").
//
// A pageable clEnqueueWriteBuffer/ReadBuffer goes through the driver's own bounce buffers at a
// quarter of the bus (H100, PCIe 5: 11-14 GB/s against 55 GB/s pinned). So each frame size gets
// device buffers and pinned host memory (CL_MEM_ALLOC_HOST_PTR, mapped once: NVIDIA's pinned
// allocation), kept and reused across calls. The caller's pixels are copied into the pinned memory
// by a few threads taking small chunks in order, each band's DMA enqueued as soon as its bytes are
// there, so the copy and the transfer overlap; the download mirrors it. Up to `max_frames` frames
// may be in flight (upload of one, kernels of the next, download of a third: the sequence
// pipeline's overlap).
// CPU devices do not come here: the kernel reads the host images in place (frame_buffers.h).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "fogcl/fog_pass.h"
#include "fogcl/image.h"
#include "runtime/clhpp.h"

namespace fogcl::detail {

// A few persistent threads for the staging copies: run(n, task) calls task(0..n-1) on them and
// on the calling thread, and returns when all have run (the first exception is rethrown).
// begin(n, task) starts the same on the threads alone and returns at once, so that the caller
// works meanwhile; the Batch's wait() then joins in and returns when all have run.
class CopyWorkers {
 public:
  explicit CopyWorkers(int threads);
  ~CopyWorkers();
  CopyWorkers(const CopyWorkers&) = delete;
  CopyWorkers& operator=(const CopyWorkers&) = delete;
  int threads() const { return int(workers_.size()) + 1; }
  // A begun batch. Destroying it waits for its tasks (dropping their exception), so that no
  // task outlives what it uses.
  class Batch {
   public:
    Batch() = default;
    Batch(Batch&& other) noexcept;
    Batch& operator=(Batch&& other) noexcept;  // waits for its own tasks first
    ~Batch();
    void wait();

   private:
    friend class CopyWorkers;
    CopyWorkers* owner_ = nullptr;
    std::unique_ptr<std::function<void(int)>> task_;
    std::unique_lock<std::mutex> batch_;
  };
  // One batch at a time: a second caller waits for the first's batch to end. Without threads,
  // or for one task, begin runs the tasks itself.
  Batch begin(int n, std::function<void(int)> task);
  void run(int n, const std::function<void(int)>& task) { begin(n, task).wait(); }

 private:
  std::mutex batch_;
  void work();
  bool take_and_run(std::unique_lock<std::mutex>& lock);
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, finished_;
  const std::function<void(int)>* task_ = nullptr;
  int next_ = 0, count_ = 0, running_ = 0;
  std::exception_ptr error_;
  bool stop_ = false;
};

class HostStaging;

// A pass's convenience-call transfers: the choice (set_host_transfer), and its context's staging
// once a staged call has run.
struct ConvenienceTransfers {
  HostTransfer choice = HostTransfer::automatic;
  std::shared_ptr<HostStaging> staging;
  // Whether calls stage their images on a device (cpu: a CPU device).
  bool staged(bool cpu) const {
    return choice == HostTransfer::staged || (choice == HostTransfer::automatic && !cpu);
  }
  HostStaging& staging_of(const cl::Context& context, const cl::Device& device);
};

struct StagingSlot;

// One frame's device buffers and pinned memory while it is in flight (HostStaging::start).
// Destroying it waits for its commands and frees the slot.
class StagedFrame {
 public:
  StagedFrame() = default;
  StagedFrame(StagedFrame&& other) noexcept;
  StagedFrame& operator=(StagedFrame&& other) noexcept;
  ~StagedFrame();
  explicit operator bool() const { return slot_ != nullptr; }

 private:
  friend class HostStaging;
  HostStaging* owner_ = nullptr;
  StagingSlot* slot_ = nullptr;
  void release();
};

class HostStaging {
 public:
  // The staging of (context, device), shared by every pass there (a frame's volumes and fog use
  // the same slots); made on first use, freed with its last holder.
  static std::shared_ptr<HostStaging> shared(const cl::Context& context, const cl::Device& device);

  // max_frames >= 1: the frames in flight whose slots stay allocated (three: upload, kernels and
  // download of consecutive frames). More may be in flight, up to 16 (then start() throws).
  HostStaging(const cl::Context& context, const cl::Device& device, int max_frames = 3);
  ~HostStaging();
  HostStaging(const HostStaging&) = delete;
  HostStaging& operator=(const HostStaging&) = delete;

  // A convenience call's round trip up to the result's download, with no host wait: in and depth
  // (same size, packed rows: image/packed_frame.h) go up through a free slot's pinned memory, the
  // depth first, its copies begun before passes is called.
  // passes(buffers, upload_depth, upload_color) enqueues the passes on the slot's device buffers:
  // it does what needs neither image meanwhile, calls upload_depth(rows), which waits for the
  // copies of the depth's rows [0, rows) (the rest go on) and returns when which rows of it are
  // on the device (at least those; all of them once every row was asked for), enqueues what reads
  // only the depth after those rows (asking for more rows as it goes),
  // then calls upload_color(), which sends the color up (the depth first, if not sent) and
  // returns the event after which color and depth are on the device, and enqueues the rest after
  // it; it returns when which rows of buffers.color_out are final (one entry for the whole frame
  // or one per band of rows), which the download into `out` follows band by band. An image that
  // passes does not send goes up after it returns. Returns once the host images may be reused
  // (the DMA from the slot may still run); an image in pinned memory of this context
  // (pinned_memory.h) crosses the bus from where it is, uncopied (then this waits for that DMA).
  //
  // Rows [the previous entry's rows_end, rows_end) are there (uploaded, or final in the output)
  // once `event` is complete; entries in ascending order, the last one ending at the frame's
  // height. (An upload's bands may complete out of order: rows_events gives all a range needs.)
  struct RowsReady {
    int rows_end;
    cl::Event event;
  };
  using UploadDepth = std::function<std::vector<RowsReady>(int rows)>;
  using UploadColor = std::function<cl::Event()>;
  using Passes = std::function<std::vector<RowsReady>(const FrameBuffers& buffers, const UploadDepth& upload_depth,
                                                      const UploadColor& upload_color)>;
  // The events after which rows [0, rows) of `ready` are there: its entries up to the first that
  // reaches `rows` (all of them past the last).
  static std::vector<cl::Event> rows_events(const std::vector<RowsReady>& ready, int rows);
  StagedFrame start(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                    const Passes& passes);
  // Threads for work on a frame's host images before start() (the upload's, idle until then; a
  // batch of another frame's upload is waited for): the volume pass's culling scan of the depth.
  CopyWorkers& scan_workers() { return up_workers_; }
  // Waits for the download and copies it into `out` (the image given to start()); then the slot
  // is free for the next frame. Thread-safe against start() of other frames.
  void finish(StagedFrame& frame, const ColorView& out);

 private:
  void download(StagedFrame& frame, const std::vector<RowsReady>& ready, const ColorView& out);
  friend class StagedFrame;
  void give_back(StagingSlot* slot);
  void unmap(StagingSlot& slot);
  StagingSlot& take_slot(int width, int height, ColorFormat format);

  cl::Context context_;
  cl::CommandQueue upload_queue_, download_queue_;
  int max_frames_;
  // Uploads (the passes' thread) and downloads (finish(), possibly another thread) copy at once.
  CopyWorkers up_workers_, down_workers_;
  mutable std::mutex mutex_;
  std::vector<std::unique_ptr<StagingSlot>> slots_;
};

}  // namespace fogcl::detail
