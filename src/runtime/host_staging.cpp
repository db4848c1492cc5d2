#include "runtime/host_staging.h"

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "runtime/pinned_memory.h"

namespace fogcl::detail {

// ---- CopyWorkers -------------------------------------------------------------------------------

CopyWorkers::CopyWorkers(int threads) {
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { work(); });
}

CopyWorkers::~CopyWorkers() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

// Runs one task of the current batch (the lock is released around it); false when none is left.
bool CopyWorkers::take_and_run(std::unique_lock<std::mutex>& lock) {
  if (task_ == nullptr || next_ >= count_) return false;
  const int i = next_++;
  ++running_;
  const std::function<void(int)>& task = *task_;
  lock.unlock();
  std::exception_ptr error;
  try {
    task(i);
  } catch (...) {
    error = std::current_exception();
  }
  lock.lock();
  if (error && !error_) error_ = error;
  if (--running_ == 0 && next_ >= count_) finished_.notify_all();
  return true;
}

void CopyWorkers::work() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stop_ || (task_ != nullptr && next_ < count_); });
    if (stop_) return;
    while (take_and_run(lock)) {
    }
  }
}

CopyWorkers::Batch CopyWorkers::begin(int n, std::function<void(int)> task) {
  Batch batch;
  if (n <= 0) return batch;
  if (workers_.empty() || n == 1) {
    for (int i = 0; i < n; ++i) task(i);
    return batch;
  }
  batch.batch_ = std::unique_lock<std::mutex>(batch_);
  batch.task_ = std::make_unique<std::function<void(int)>>(std::move(task));
  batch.owner_ = this;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    task_ = batch.task_.get();
    next_ = 0;
    count_ = n;
    error_ = nullptr;
  }
  wake_.notify_all();
  return batch;
}

CopyWorkers::Batch::Batch(Batch&& other) noexcept
    : owner_(std::exchange(other.owner_, nullptr)), task_(std::move(other.task_)), batch_(std::move(other.batch_)) {}

CopyWorkers::Batch& CopyWorkers::Batch::operator=(Batch&& other) noexcept {
  if (this != &other) {
    try {
      wait();
    } catch (...) {  // as the destructor
    }
    owner_ = std::exchange(other.owner_, nullptr);
    task_ = std::move(other.task_);
    batch_ = std::move(other.batch_);
  }
  return *this;
}

CopyWorkers::Batch::~Batch() {
  try {
    wait();
  } catch (...) {  // the caller is unwinding from an error of its own, or never asked
  }
}

void CopyWorkers::Batch::wait() {
  if (owner_ == nullptr) return;
  CopyWorkers& w = *std::exchange(owner_, nullptr);
  std::exception_ptr error;
  {
    std::unique_lock<std::mutex> lock(w.mutex_);
    while (w.take_and_run(lock)) {
    }
    w.finished_.wait(lock, [&] { return w.running_ == 0 && w.next_ >= w.count_; });
    w.task_ = nullptr;
    error = std::exchange(w.error_, nullptr);
  }
  batch_.unlock();
  if (error) std::rethrow_exception(error);
}

// ---- slots -------------------------------------------------------------------------------------

namespace {
// Bands of ~2 MiB: large enough for the DMA engine's full rate, small enough that the first
// transfer starts early and the copies spread over the threads. (First and last bands from
// 256 KiB up, to shorten the pipeline's fill and drain, measured no faster on the H200's host.)
constexpr std::size_t kBandBytes = std::size_t(2) << 20;
// A caller that never waits must not exhaust memory.
constexpr long kMaxInFlight = 16;

// The copies between the caller's memory and a band are split into chunks that the threads take
// in order, so that all of them fill (or empty) the first band together and its DMA starts after
// a chunk's worth of time per thread. One thread per band made every band finish at once: at
// 1080p RGBA16F (8 bands, 8 threads) the color crossed the bus only after all of it was copied.
constexpr std::size_t kChunkBytes = std::size_t(256) << 10;

struct Band {
  std::size_t offset, bytes;
};
std::vector<Band> bands(std::size_t total) {
  const std::size_t n = std::max<std::size_t>(1, (total + kBandBytes - 1) / kBandBytes);
  const std::size_t per = ((total + n - 1) / n + 4095) / 4096 * 4096;  // page multiples
  std::vector<Band> out;
  for (std::size_t at = 0; at < total; at += per) out.push_back({at, std::min(per, total - at)});
  return out;
}
// A band's chunks, band by band in order: `band` indexes the bands.
struct Chunk {
  std::size_t band, offset, bytes;
};
std::vector<Chunk> chunks(const std::vector<Band>& in_bands) {
  std::vector<Chunk> out;
  for (std::size_t b = 0; b < in_bands.size(); ++b)
    for (std::size_t at = 0; at < in_bands[b].bytes; at += kChunkBytes)
      out.push_back({b, in_bands[b].offset + at, std::min(kChunkBytes, in_bands[b].bytes - at)});
  return out;
}
}  // namespace

struct StagingSlot {
  int width = 0, height = 0;
  ColorFormat format = ColorFormat::rgba32f;
  bool busy = false;
  cl::Buffer color_in, depth, color_out;  // on the device
  cl::Buffer pinned_in, pinned_out;       // host memory the driver has pinned, mapped for the slot's life
  std::byte* in = nullptr;                // pinned_in: color, then depth
  std::byte* out = nullptr;               // pinned_out: color
  FrameBuffers raw;
  cl::Event uploaded;
  std::vector<cl::Event> after;           // the passes' events that the download follows
  std::vector<cl::Event> depth_ready;     // the depth's transfers, sent before the color
  std::vector<cl::Event> downloads;       // one per band of color_out
  bool out_direct = false;                // downloaded into the caller's pinned image itself
  std::size_t color_bytes() const { return color_buffer_bytes(width, height, format); }
  std::size_t depth_bytes() const { return depth_buffer_bytes(width, height); }
};

// ---- StagedFrame -------------------------------------------------------------------------------

StagedFrame::StagedFrame(StagedFrame&& other) noexcept
    : owner_(std::exchange(other.owner_, nullptr)), slot_(std::exchange(other.slot_, nullptr)) {}

StagedFrame& StagedFrame::operator=(StagedFrame&& other) noexcept {
  if (this != &other) {
    release();
    owner_ = std::exchange(other.owner_, nullptr);
    slot_ = std::exchange(other.slot_, nullptr);
  }
  return *this;
}

StagedFrame::~StagedFrame() { release(); }

// A frame given up before finish(): its commands may still use the slot's memory.
void StagedFrame::release() {
  if (slot_ == nullptr) return;
  StagingSlot* s = std::exchange(slot_, nullptr);
  try {
    for (cl::Event& e : s->depth_ready) e.wait();
    if (s->uploaded()) s->uploaded.wait();
    for (cl::Event& e : s->after) e.wait();
    for (cl::Event& e : s->downloads) e.wait();
  } catch (...) {
    // A failed command is over, too: the slot can be reused.
  }
  owner_->give_back(s);
}

// ---- HostStaging -------------------------------------------------------------------------------

namespace {
// The bus moves 54 GB/s each way, one core's memcpy ~10 (H100 host): 8 threads copy 45-49 GB/s
// with memcpy, 12 or 16 no more (bench/results/gpu-h100-2026-11-25-round-trip/band-sweep.md);
// band_copy's non-temporal stores keep up with the bus. At most the CPUs this process may run on.
int copy_threads() {
  cpu_set_t set;
  const int cpus = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set)
                                                                : int(std::thread::hardware_concurrency());
  return std::clamp(cpus, 1, 8);
}

// A band's copy between the caller's memory and the pinned memory, with non-temporal stores
// where the CPU has them (SSE2, every x86-64): an ordinary store first reads the line it
// overwrites, so a copy moves three times its bytes through DRAM instead of two, and none of
// these bytes is read again by the CPU (the DMA reads the pinned ones, the caller the rest later).
void band_copy(std::byte* dst, const std::byte* src, std::size_t n) {
#if defined(__SSE2__)
  std::size_t i = std::min(n, (16 - reinterpret_cast<std::uintptr_t>(dst) % 16) % 16);
  std::memcpy(dst, src, i);
  for (; i + 64 <= n; i += 64) {
    const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(src + i));
    const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(src + i + 16));
    const __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i*>(src + i + 32));
    const __m128i d = _mm_loadu_si128(reinterpret_cast<const __m128i*>(src + i + 48));
    _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i), a);
    _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i + 16), b);
    _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i + 32), c);
    _mm_stream_si128(reinterpret_cast<__m128i*>(dst + i + 48), d);
  }
  std::memcpy(dst + i, src + i, n - i);
  _mm_sfence();  // the stores are visible before the DMA is enqueued or the frame handed back
#else
  std::memcpy(dst, src, n);
#endif
}
}  // namespace

HostStaging& ConvenienceTransfers::staging_of(const cl::Context& context, const cl::Device& device) {
  if (staging == nullptr) staging = HostStaging::shared(context, device);
  return *staging;
}

std::shared_ptr<HostStaging> HostStaging::shared(const cl::Context& context, const cl::Device& device) {
  static std::mutex mutex;
  static std::map<std::pair<cl_context, cl_device_id>, std::weak_ptr<HostStaging>> stagings;
  const std::lock_guard<std::mutex> lock(mutex);
  // A live staging retains its context, so a key's handle is not reused while its entry can lock.
  std::weak_ptr<HostStaging>& entry = stagings[{context(), device()}];
  std::shared_ptr<HostStaging> staging = entry.lock();
  if (staging == nullptr) {
    staging = std::make_shared<HostStaging>(context, device);
    entry = staging;
  }
  return staging;
}

HostStaging::HostStaging(const cl::Context& context, const cl::Device& device, int max_frames)
    : context_(context),
      upload_queue_(context, device),
      download_queue_(context, device),
      max_frames_(std::max(1, max_frames)),
      up_workers_(copy_threads()),
      down_workers_(copy_threads()) {}

HostStaging::~HostStaging() {
  try {
    upload_queue_.finish();
    download_queue_.finish();
    for (auto& s : slots_) unmap(*s);
  } catch (...) {
  }
}

void HostStaging::give_back(StagingSlot* slot) {
  std::lock_guard<std::mutex> lock(mutex_);
  slot->busy = false;
  slot->uploaded = cl::Event();
  slot->after.clear();
  slot->depth_ready.clear();
  slot->downloads.clear();
  slot->out_direct = false;
  // Frames beyond max_frames in flight got slots of their own: keep max_frames slots' memory.
  if (int(slots_.size()) > max_frames_) {
    const auto it = std::find_if(slots_.begin(), slots_.end(), [&](const auto& s) { return s.get() == slot; });
    unmap(*slot);
    slots_.erase(it);
  }
}

void HostStaging::unmap(StagingSlot& s) {
  upload_queue_.enqueueUnmapMemObject(s.pinned_in, s.in);
  upload_queue_.enqueueUnmapMemObject(s.pinned_out, s.out);
  upload_queue_.finish();
}

StagingSlot& HostStaging::take_slot(int width, int height, ColorFormat format) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& s : slots_)
    if (!s->busy && s->width == width && s->height == height && s->format == format) {
      s->busy = true;
      return *s;
    }
  const auto busy = std::count_if(slots_.begin(), slots_.end(), [](const auto& s) { return s->busy; });
  if (busy >= kMaxInFlight)
    throw Error("more than " + std::to_string(kMaxInFlight) +
                " staged frames in flight: wait() for earlier frames before starting more");
  // A new size (or every slot busy): drop a free slot of another size first, keeping at most
  // max_frames slots' memory.
  if (int(slots_.size()) >= max_frames_) {
    const auto idle = std::find_if(slots_.begin(), slots_.end(), [](const auto& s) { return !s->busy; });
    if (idle != slots_.end()) {
      unmap(**idle);
      slots_.erase(idle);
    }
  }
  auto s = std::make_unique<StagingSlot>();
  s->width = width;
  s->height = height;
  s->format = format;
  const std::size_t color = s->color_bytes(), depth = s->depth_bytes();
  s->color_in = cl::Buffer(context_, CL_MEM_READ_WRITE, color);
  s->depth = cl::Buffer(context_, CL_MEM_READ_ONLY, depth);
  s->color_out = cl::Buffer(context_, CL_MEM_READ_WRITE, color);
  s->pinned_in = cl::Buffer(context_, CL_MEM_READ_ONLY | CL_MEM_ALLOC_HOST_PTR, color + depth);
  s->pinned_out = cl::Buffer(context_, CL_MEM_WRITE_ONLY | CL_MEM_ALLOC_HOST_PTR, color);
  s->in = static_cast<std::byte*>(upload_queue_.enqueueMapBuffer(s->pinned_in, CL_TRUE, CL_MAP_WRITE, 0, color + depth));
  s->out = static_cast<std::byte*>(upload_queue_.enqueueMapBuffer(s->pinned_out, CL_TRUE, CL_MAP_READ, 0, color));
  s->raw.width = width;
  s->raw.height = height;
  s->raw.format = format;
  s->raw.color_in = s->color_in();
  s->raw.depth = s->depth();
  s->raw.color_out = s->color_out();
  s->busy = true;
  slots_.push_back(std::move(s));
  return *slots_.back();
}

namespace {
// One image's bytes (`rows` rows) on their way to a device buffer of a slot, from construction:
// where the image is pinned memory of the context, straight from it (direct()); else band by
// band through the slot's pinned memory at `pinned`, the copies on `workers` while the caller
// goes on, each band's DMA enqueued by the thread that copies its last chunk. ready() waits for
// the copies and returns the rows each transfer completes; ready_rows(rows) waits only for the
// bands that hold rows [0, rows). Not ready()'d when destroyed (an error upstream), it waits for
// its transfers, which read memory the caller may then reuse.
class ImageUpload {
 public:
  ImageUpload(CopyWorkers& workers, const cl::CommandQueue& queue, const cl::Context& context, const std::byte* src,
              std::size_t bytes, int rows, const cl::Buffer& to, std::byte* pinned)
      : rows_(rows), bytes_(bytes), direct_(is_pinned(src, bytes, context())) {
    if (direct_) {
      done_.resize(1);
      queue.enqueueWriteBuffer(to, CL_FALSE, 0, bytes, src, nullptr, &done_[0]);
      return;
    }
    bands_ = bands(bytes);
    done_.resize(bands_.size());
    // Chunks not yet copied per band: the thread that copies a band's last one sends the band.
    left_ = std::make_unique<std::atomic<std::size_t>[]>(bands_.size());
    for (std::size_t b = 0; b < bands_.size(); ++b)
      left_[b].store((bands_[b].bytes + kChunkBytes - 1) / kChunkBytes, std::memory_order_relaxed);
    sent_.assign(bands_.size(), false);
    std::vector<Chunk> image_chunks = chunks(bands_);
    const int n = int(image_chunks.size());
    copies_ = workers.begin(n, [this, image_chunks = std::move(image_chunks), &queue, to, src, pinned](int i) {
      const Chunk c = image_chunks[i];
      band_copy(pinned + c.offset, src + c.offset, c.bytes);
      if (left_[c.band].fetch_sub(1, std::memory_order_acq_rel) != 1) return;
      const Band b = bands_[c.band];
      bool sent = false;
      try {
        queue.enqueueWriteBuffer(to, CL_FALSE, b.offset, b.bytes, pinned + b.offset, nullptr, &done_[c.band]);
        sent = true;
      } catch (...) {
        mark(c.band, sent);  // a waiting ready_rows() learns of the failure from copies_
        throw;
      }
      mark(c.band, sent);
    });
  }
  ImageUpload(const ImageUpload&) = delete;
  ImageUpload& operator=(const ImageUpload&) = delete;
  ~ImageUpload() {
    try {
      copies_.wait();  // first: its tasks use the members
    } catch (...) {  // an error upstream is on its way already
    }
    if (!readied_)
      for (cl::Event& e : done_)
        if (e() != nullptr) e.wait();
  }
  bool direct() const { return direct_; }
  std::vector<HostStaging::RowsReady> ready() {
    copies_.wait();
    readied_ = true;
    return rows_ready(bands_.size());
  }
  // The entries of rows [0, rows), once the bands that hold them are sent: the copies of later
  // bands go on. ready() still has to be called for the whole image.
  std::vector<HostStaging::RowsReady> ready_rows(int rows) {
    if (direct_) return ready();
    std::size_t needed = 1;  // bands up to the first that completes the rows
    while (needed < bands_.size() && rows_end(needed - 1) < rows) ++needed;
    if (needed == bands_.size()) return ready();  // the whole image: its copies' batch ends here
    std::unique_lock<std::mutex> lock(sent_mutex_);
    sent_cv_.wait(lock, [&] {
      return failed_ || std::all_of(sent_.begin(), sent_.begin() + std::ptrdiff_t(needed), [](bool b) { return b; });
    });
    if (failed_) {
      lock.unlock();
      ready();  // rethrows the copy thread's error
    }
    return rows_ready(needed);
  }

 private:
  void mark(std::size_t band, bool sent) {
    {
      const std::lock_guard<std::mutex> lock(sent_mutex_);
      if (sent)
        sent_[band] = true;
      else
        failed_ = true;
    }
    sent_cv_.notify_all();
  }
  // A band's DMA completes the rows that end within it, once those of the bands before it are
  // done too (the threads may enqueue bands out of order).
  int rows_end(std::size_t band) const {
    const Band& b = bands_[band];
    return band + 1 == bands_.size() ? rows_ : int((b.offset + b.bytes) / (bytes_ / std::size_t(rows_)));
  }
  // The first n bands' entries.
  std::vector<HostStaging::RowsReady> rows_ready(std::size_t n) const {
    if (direct_) return {{rows_, done_[0]}};
    std::vector<HostStaging::RowsReady> out;
    for (std::size_t b = 0; b < n; ++b) out.push_back({rows_end(b), done_[b]});
    return out;
  }

  int rows_;
  std::size_t bytes_;
  bool direct_, readied_ = false;
  std::vector<Band> bands_;
  std::vector<cl::Event> done_;
  std::unique_ptr<std::atomic<std::size_t>[]> left_;
  std::mutex sent_mutex_;  // guards sent_ and failed_
  std::condition_variable sent_cv_;
  std::vector<bool> sent_;  // per band: its DMA is enqueued (done_ holds its event)
  bool failed_ = false;     // a band's enqueue threw
  CopyWorkers::Batch copies_;
};
}  // namespace

std::vector<cl::Event> HostStaging::rows_events(const std::vector<RowsReady>& ready, int rows) {
  std::vector<cl::Event> events;
  for (const RowsReady& r : ready) {
    events.push_back(r.event);
    if (r.rows_end >= rows) break;
  }
  return events;
}

StagedFrame HostStaging::start(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                    const Passes& passes) {
  StagedFrame frame;
  frame.owner_ = this;
  frame.slot_ = &take_slot(in.width(), in.height(), in.format());
  StagingSlot& s = *frame.slot_;
  // A throw before the download is queued drops `frame`, which waits for what was enqueued.
  // The depth goes first, so that what reads only the depth (the volumes' march) runs while the
  // color is copied and crosses the bus.
  // The depth's copies start now, while passes prepares its work.
  ImageUpload depth_up(up_workers_, upload_queue_, context_, reinterpret_cast<const std::byte*>(depth.data()),
                       s.depth_bytes(), s.height, s.depth, s.in + s.color_bytes());
  std::optional<ImageUpload> color_up;
  std::vector<RowsReady> depth_rows;  // all of the depth's, once all of it is sent
  const UploadDepth upload_depth = [&](int rows) {
    if (!depth_rows.empty()) return depth_rows;
    std::vector<RowsReady> ready = depth_up.ready_rows(rows);
    upload_queue_.flush();
    if (ready.back().rows_end < s.height) return ready;
    depth_rows = std::move(ready);
    for (const RowsReady& r : depth_rows) s.depth_ready.push_back(r.event);
    return depth_rows;
  };
  const UploadColor upload_color = [&] {
    if (color_up) throw Error("HostStaging: the color was uploaded twice");
    if (depth_rows.empty()) upload_depth(s.height);
    color_up.emplace(up_workers_, upload_queue_, context_, static_cast<const std::byte*>(in.data()), s.color_bytes(),
                     s.height, s.color_in, s.in);
    color_up->ready();
    upload_queue_.enqueueMarkerWithWaitList(nullptr, &s.uploaded);
    upload_queue_.flush();
    return s.uploaded;
  };
  const std::vector<RowsReady> ready = passes(s.raw, upload_depth, upload_color);
  if (!color_up) upload_color();  // every frame sends both images: `uploaded` ends the upload
  // The caller may change its images once this returns: the DMA from them must be over.
  if (color_up->direct() || depth_up.direct()) s.uploaded.wait();
  download(frame, ready, out);
  return frame;
}

void HostStaging::download(StagedFrame& frame, const std::vector<RowsReady>& ready, const ColorView& out) {
  StagingSlot& s = *frame.slot_;
  if (ready.empty() || ready.back().rows_end != s.height)
    throw Error("HostStaging: the passes' rows do not end at the frame's last row");
  for (const RowsReady& r : ready) s.after.push_back(r.event);
  auto* dst = static_cast<std::byte*>(out.data());
  s.out_direct = is_pinned(dst, s.color_bytes(), context_());
  const std::size_t row_bytes = s.color_bytes() / std::size_t(s.height);
  for (const Band& b : bands(s.color_bytes())) {
    // The band waits for the passes' events of the rows it holds.
    const int first = int(b.offset / row_bytes), last = int((b.offset + b.bytes - 1) / row_bytes);
    std::vector<cl::Event> wait;
    int begin = 0;
    for (const RowsReady& r : ready) {
      if (r.rows_end > first && begin <= last) wait.push_back(r.event);
      begin = r.rows_end;
    }
    cl::Event e;
    download_queue_.enqueueReadBuffer(s.color_out, CL_FALSE, b.offset, b.bytes, (s.out_direct ? dst : s.out) + b.offset,
                                      &wait, &e);
    s.downloads.push_back(e);
  }
  download_queue_.flush();
}

void HostStaging::finish(StagedFrame& frame, const ColorView& out) {
  if (!frame) return;
  StagingSlot& s = *frame.slot_;
  if (s.downloads.empty()) throw Error("HostStaging::finish: the frame's download was never enqueued");
  const std::vector<Chunk> color_chunks = chunks(bands(s.color_bytes()));
  auto* dst = static_cast<std::byte*>(out.data());
  // A band is copied out, chunk by chunk by every thread, as soon as its DMA is done, while later
  // bands still cross the bus.
  down_workers_.run(int(color_chunks.size()), [&](int i) {
    const Chunk c = color_chunks[i];
    s.downloads[c.band].wait();
    if (!s.out_direct) band_copy(dst + c.offset, s.out + c.offset, c.bytes);
  });
  frame.release();
}

}  // namespace fogcl::detail
