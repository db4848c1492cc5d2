#include <algorithm>
#include <array>

#include "fogcl/external_memory.h"
#include "interop/khr_functions.h"
#include "runtime/frame_buffers.h"

namespace fogcl {

namespace {

// One image of the frame: used where it lies (a sub-buffer, or the imported buffer itself) or
// through a packed scratch buffer with rectangle copies on the device.
struct Plane {
  const ExternalMemory* memory = nullptr;
  std::size_t offset = 0, row_pitch = 0, row_bytes = 0;
  int height = 0;
  bool staged = false;
  cl::Buffer packed;  // what the pass gets

  std::size_t extent() const { return row_pitch * std::size_t(height - 1) + row_bytes; }
  std::size_t end() const { return offset + extent(); }
};

bool overlap(const Plane& a, const Plane& b) {
  return a.memory == b.memory && a.offset < b.end() && b.offset < a.end();
}

Plane make_plane(const cl::Context& context, const ExternalPlane& p, const char* name, std::size_t pixel_bytes,
                 int width, int height, std::size_t base_align) {
  if (p.memory == nullptr) throw Error(std::string("ExternalFrame: ") + name + ".memory is null");
  Plane out;
  out.memory = p.memory;
  out.offset = p.offset;
  out.row_bytes = std::size_t(width) * pixel_bytes;
  out.row_pitch = p.row_pitch == 0 ? out.row_bytes : p.row_pitch;
  out.height = height;
  if (out.row_pitch < out.row_bytes)
    throw Error(std::string("ExternalFrame: ") + name + ".row_pitch " + std::to_string(out.row_pitch) +
                " bytes is below a row's " + std::to_string(out.row_bytes) + " (" + std::to_string(width) + " x " +
                std::to_string(pixel_bytes) + " bytes)");
  if (out.row_pitch % 4 != 0 || out.offset % 4 != 0)
    throw Error(std::string("ExternalFrame: ") + name + " needs an offset and a row pitch that are multiples of 4 " +
                "bytes (got offset " + std::to_string(out.offset) + ", row pitch " + std::to_string(out.row_pitch) +
                ")");
  if (out.offset > p.memory->size() || out.extent() > p.memory->size() - out.offset)
    throw Error(std::string("ExternalFrame: ") + name + " ends at byte " + std::to_string(out.end()) +
                " (offset " + std::to_string(out.offset) + ", row pitch " + std::to_string(out.row_pitch) + ", " +
                std::to_string(height) + " rows) beyond its imported memory's " + std::to_string(p.memory->size()) +
                " bytes");
  const std::size_t packed_bytes = out.row_bytes * std::size_t(height);
  out.staged = out.row_pitch != out.row_bytes || out.offset % base_align != 0;
  with_cl_errors([&] {
    cl::Buffer whole(p.memory->buffer(), true);
    if (out.staged) {
      out.packed = cl::Buffer(context, CL_MEM_READ_WRITE, packed_bytes);
    } else if (out.offset == 0 && packed_bytes == p.memory->size()) {
      out.packed = whole;
    } else {
      cl_buffer_region region{out.offset, packed_bytes};
      out.packed = whole.createSubBuffer(CL_MEM_READ_WRITE, CL_BUFFER_CREATE_TYPE_REGION, &region);
    }
  });
  return out;
}

void check(cl_int err, const char* call) {
  if (err != CL_SUCCESS) throw ClError(call, err);
}

}  // namespace

struct ExternalFrame::Impl {
  cl::Context context;
  cl::Device device;
  const detail::KhrFunctions* fns = nullptr;
  Plane color_in, depth, color_out;
  bool in_place = false;
  std::vector<cl_mem> imported;  // distinct allocations, acquired and released around the pass
  FrameBuffers frame;

  // A rectangle copy between a plane where it lies and its packed scratch, after `waits`.
  cl::Event copy(const cl::CommandQueue& queue, const Plane& p, bool into_scratch, const std::vector<cl_event>& waits) {
    const std::array<std::size_t, 3> where{p.offset, 0, 0}, zero{0, 0, 0}, region{p.row_bytes, std::size_t(p.height), 1};
    cl_event e = nullptr;
    const cl_mem lying = p.memory->buffer();
    check(clEnqueueCopyBufferRect(queue(), into_scratch ? lying : p.packed(), into_scratch ? p.packed() : lying,
                                  into_scratch ? where.data() : zero.data(), into_scratch ? zero.data() : where.data(),
                                  region.data(), into_scratch ? p.row_pitch : p.row_bytes, 0,
                                  into_scratch ? p.row_bytes : p.row_pitch, 0, cl_uint(waits.size()),
                                  waits.empty() ? nullptr : waits.data(), &e),
          "clEnqueueCopyBufferRect");
    return cl::Event(e, false);
  }
};

ExternalFrame::ExternalFrame(cl_context context, cl_device_id device, const ExternalFrameLayout& layout)
    : impl_(std::make_unique<Impl>()) {
  if (context == nullptr || device == nullptr)
    throw Error("ExternalFrame needs a context and a device (got a null handle)");
  if (layout.width < 1 || layout.height < 1)
    throw Error("ExternalFrame: frame size must be at least 1x1 (got " + std::to_string(layout.width) + "x" +
                std::to_string(layout.height) + ")");
  Impl& m = *impl_;
  m.context = wrap(context);
  m.device = wrap(device);
  m.fns = &detail::khr_functions(device);
  if (m.fns->acquire == nullptr || m.fns->release == nullptr)
    throw Error("ExternalFrame: device '" + device_name(device) + "' returns no clEnqueueAcquireExternalMemObjectsKHR "
                "(cl_khr_external_memory)");
  const cl_uint align_bits = with_cl_errors([&] { return m.device.getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>(); });
  const std::size_t align = std::max<std::size_t>(align_bits / 8, 1);
  const std::size_t color_bytes = bytes_per_pixel(layout.format);
  const int w = layout.width, h = layout.height;
  m.color_in = make_plane(m.context, layout.color_in, "color_in", color_bytes, w, h, align);
  m.depth = make_plane(m.context, layout.depth, "depth", sizeof(float), w, h, align);
  const ExternalPlane& out = layout.color_out;
  m.in_place = out.memory == nullptr ||
               (out.memory == layout.color_in.memory && out.offset == layout.color_in.offset &&
                (out.row_pitch == 0 ? color_bytes * std::size_t(w) : out.row_pitch) == m.color_in.row_pitch);
  if (overlap(m.color_in, m.depth)) throw Error("ExternalFrame: color_in and depth overlap in their memory");
  if (!m.in_place) {
    m.color_out = make_plane(m.context, out, "color_out", color_bytes, w, h, align);
    if (overlap(m.color_out, m.color_in))
      throw Error("ExternalFrame: color_out overlaps color_in without being the same plane (in place)");
    if (overlap(m.color_out, m.depth)) throw Error("ExternalFrame: color_out overlaps depth");
  }
  for (const Plane* p : {&m.color_in, &m.depth, m.in_place ? nullptr : &m.color_out})
    if (p != nullptr && std::find(m.imported.begin(), m.imported.end(), p->memory->buffer()) == m.imported.end())
      m.imported.push_back(p->memory->buffer());
  m.frame.width = w;
  m.frame.height = h;
  m.frame.format = layout.format;
  m.frame.color_in = m.color_in.packed();
  m.frame.depth = m.depth.packed();
  m.frame.color_out = m.in_place ? m.frame.color_in : m.color_out.packed();
}

ExternalFrame::~ExternalFrame() = default;
ExternalFrame::ExternalFrame(ExternalFrame&&) noexcept = default;
ExternalFrame& ExternalFrame::operator=(ExternalFrame&&) noexcept = default;
const FrameBuffers& ExternalFrame::buffers() const { return impl_->frame; }
bool ExternalFrame::zero_copy() const {
  return !impl_->color_in.staged && !impl_->depth.staged && (impl_->in_place || !impl_->color_out.staged);
}

cl_event ExternalFrame::enqueue(cl_command_queue queue_handle, const PassFn& run, const ExternalSync& sync) {
  Impl& m = *impl_;
  if (!run) throw Error("ExternalFrame::enqueue: no pass to run");
  std::vector<cl_semaphore_khr> waits, signals;
  for (const ExternalSemaphore* s : sync.wait) {
    if (s == nullptr || s->handle() == nullptr) throw Error("ExternalFrame::enqueue: a wait semaphore is null");
    waits.push_back(s->handle());
  }
  for (const ExternalSemaphore* s : sync.signal) {
    if (s == nullptr || s->handle() == nullptr) throw Error("ExternalFrame::enqueue: a signal semaphore is null");
    signals.push_back(s->handle());
  }
  if ((!waits.empty() || !signals.empty()) && (m.fns->wait_semaphores == nullptr || m.fns->signal_semaphores == nullptr))
    throw Error("ExternalFrame::enqueue: semaphores given, but device '" + device_name(m.device()) +
                "' returns no clEnqueueWaitSemaphoresKHR/clEnqueueSignalSemaphoresKHR (cl_khr_semaphore)");
  return with_cl_errors([&] {
    const cl::CommandQueue queue = detail::checked_queue(queue_handle, m.context, m.device, "ExternalFrame::enqueue");
    // Each command waits for the previous one's event: the caller's queue may be out of order.
    std::vector<cl::Event> held;  // keeps the events alive until the end of the call
    std::vector<cl_event> after(sync.wait_events.begin(), sync.wait_events.end());
    auto then = [&](cl_event e) {
      held.emplace_back(e, false);
      after.assign(1, e);
    };
    cl_event e = nullptr;
    if (!waits.empty()) {
      check(m.fns->wait_semaphores(queue(), cl_uint(waits.size()), waits.data(), nullptr, cl_uint(after.size()),
                                   after.empty() ? nullptr : after.data(), &e),
            "clEnqueueWaitSemaphoresKHR");
      then(e);
    }
    // Release and signal: also when the pass throws, so that the renderer never waits forever
    // on a frame that failed (it keeps its unfogged pixels then).
    bool acquired = false;
    auto finish = [&] {
      if (acquired) {
        check(m.fns->release(queue(), cl_uint(m.imported.size()), m.imported.data(), cl_uint(after.size()),
                             after.empty() ? nullptr : after.data(), &e),
              "clEnqueueReleaseExternalMemObjectsKHR");
        then(e);
      }
      if (!signals.empty()) {
        check(m.fns->signal_semaphores(queue(), cl_uint(signals.size()), signals.data(), nullptr,
                                       cl_uint(after.size()), after.empty() ? nullptr : after.data(), &e),
              "clEnqueueSignalSemaphoresKHR");
        then(e);
      }
      check(clFlush(queue()), "clFlush");
    };
    try {
      check(m.fns->acquire(queue(), cl_uint(m.imported.size()), m.imported.data(), cl_uint(after.size()),
                           after.empty() ? nullptr : after.data(), &e),
            "clEnqueueAcquireExternalMemObjectsKHR");
      then(e);
      acquired = true;
      std::vector<cl_event> copies_in;
      for (const Plane* p : {&m.color_in, &m.depth})
        if (p->staged) {
          held.push_back(m.copy(queue, *p, true, after));
          copies_in.push_back(held.back()());
        }
      if (!copies_in.empty()) after = copies_in;
      const cl_event ran = run(m.frame, after);
      if (ran == nullptr) throw Error("ExternalFrame::enqueue: the pass returned no event");
      then(ran);
      const Plane& out = m.in_place ? m.color_in : m.color_out;
      if (out.staged) {
        held.push_back(m.copy(queue, out, false, after));
        after.assign(1, held.back()());
      }
    } catch (...) {
      after.clear();  // everything enqueued so far
      for (const cl::Event& h : held) after.push_back(h());
      finish();
      throw;
    }
    finish();
    return share(held.back());
  });
}

cl_event ExternalFrame::enqueue(FogPass& pass, cl_command_queue queue, const CameraParams& camera,
                                const FogSettings& settings, const ExternalSync& sync) {
  return enqueue(
      queue, [&](const FrameBuffers& fb, const std::vector<cl_event>& w) { return pass.enqueue(queue, fb, camera, settings, w); },
      sync);
}

cl_event ExternalFrame::enqueue(VolumePass& pass, cl_command_queue queue, const CameraParams& camera,
                                const VolumeScene& scene, const VolumeSettings& settings, const ExternalSync& sync,
                                const ShadowMapBuffer* shadow) {
  return enqueue(
      queue,
      [&](const FrameBuffers& fb, const std::vector<cl_event>& w) {
        return pass.enqueue(queue, fb, camera, scene, settings, shadow, w);
      },
      sync);
}

}  // namespace fogcl
