// Frames in another API's GPU memory (fogcl/external_memory.h). A CUDA producer stands in for the
// renderer: it writes frames into memory it exports, fogcl fogs them where they lie, CUDA reads
// them back; they must equal FogPass::apply on host images bit for bit. Semaphores come from
// Vulkan (CUDA imports semaphores but makes none to export, and NVIDIA's OpenCL exports none).
// These run on the GPU machine (scripts/gpu-run.sh); elsewhere they skip saying why, except the
// refusal of a device without the extension, which CI's PoCL runs.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "../examples/cuda_driver.h"
#include "../examples/vulkan_semaphores.h"
#include "fogcl/external_memory.h"
#include "test_support.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

bool fd_open(int fd) { return fcntl(fd, F_GETFD) != -1; }

// A device without external memory (PoCL) refuses with one error naming the extension, and the
// file descriptor stays the caller's.
TEST(ExternalInterop, DeviceWithoutTheExtensionRefusesNamingIt) {
  FOGCL_REQUIRE_DEVICE();
  const cl_device_id device = runtime()->device();
  const ExternalSupport support = external_support(device);
  std::printf("[ info ] %s: %s\n", device_name(device).c_str(), support.describe().c_str());
  if (support.memory_extension)
    GTEST_SKIP() << device_name(device) << " offers cl_khr_external_memory: the refusal cannot happen on it";
  EXPECT_TRUE(support.memory_imports.empty());
  const int fd = open("/dev/null", O_RDONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  const std::string memory_error = error_of([&] { ExternalMemory(runtime()->context(), device, fd, 4096); });
  EXPECT_NE(memory_error.find("does not offer cl_khr_external_memory"), std::string::npos) << memory_error;
  EXPECT_NE(memory_error.find(device_name(device)), std::string::npos) << memory_error;
  EXPECT_TRUE(fd_open(fd)) << "a refused import must leave the fd to the caller";
  if (!support.semaphore_extension) {
    const std::string import_error =
        error_of([&] { ExternalSemaphore::import_fd(runtime()->context(), device, fd); });
    EXPECT_NE(import_error.find("does not offer cl_khr_external_semaphore"), std::string::npos) << import_error;
    const std::string export_error = error_of([&] { ExternalSemaphore::exportable(runtime()->context(), device); });
    EXPECT_NE(export_error.find("does not offer cl_khr_external_semaphore"), std::string::npos) << export_error;
    EXPECT_TRUE(fd_open(fd));
  }
  std::printf("[ info ] refusal: %s\n", memory_error.c_str());
  close(fd);
}

// ---------------------------------------------------------------------------------------------
// The CUDA side, opened once: why not, when it cannot be.
struct CudaSide {
  cuda::Driver cu;
  cuda::CUdevice device = 0;
  cuda::CUcontext context = nullptr;
  unsigned char uuid[16] = {};
  std::string why_not;
};

CudaSide& cuda_side() {
  static CudaSide* side = [] {
    auto* s = new CudaSide;
    if (runtime() == nullptr) {
      s->why_not = "no OpenCL device: " + runtime_error();
      return s;
    }
    const cl_device_id device = runtime()->device();
    const ExternalSupport support = external_support(device);
    if (!support.imports_memory(ExternalHandle::opaque_fd)) {
      s->why_not = device_name(device) + " imports no opaque-fd memory (" + support.describe() + ")";
      return s;
    }
    if (clGetDeviceInfo(device, CL_DEVICE_UUID_KHR, 16, s->uuid, nullptr) != CL_SUCCESS) {
      s->why_not = device_name(device) + " reports no CL_DEVICE_UUID_KHR to find its CUDA device by";
      return s;
    }
    if (!s->cu.load(s->why_not)) return s;
    s->why_not = s->cu.open_device(s->uuid, s->device, s->context);
    return s;
  }();
  if (side->context != nullptr) side->cu.cuCtxSetCurrent(side->context);
  return *side;
}

#define FOGCL_REQUIRE_CUDA_INTEROP()                                                          \
  do {                                                                                        \
    if (!cuda_side().why_not.empty()) GTEST_SKIP() << "no CUDA interop: " << cuda_side().why_not; \
  } while (0)

#define CU_OK(call) ASSERT_EQ(cuda_side().cu.error((call), #call), "")

// Where a layout puts its planes in one allocation, and what that allocation holds.
struct Placement {
  std::size_t color_in = 0, depth = 0, color_out = 0, color_pitch = 0, depth_pitch = 0, bytes = 0;
  bool in_place = true;
};

// packed: planes one after the other, each offset a multiple of 64 KiB (sub-buffers);
// pitched: rows padded by 260 bytes and planes 4 bytes off alignment (rectangle copies).
Placement place(int w, int h, ColorFormat f, bool pitched, bool in_place) {
  Placement p;
  p.in_place = in_place;
  const std::size_t color_row = std::size_t(w) * bytes_per_pixel(f), depth_row = std::size_t(w) * 4;
  p.color_pitch = pitched ? color_row + 260 : color_row;
  p.depth_pitch = pitched ? depth_row + 260 : depth_row;
  auto next = [&](std::size_t at) { return (at + 65535) / 65536 * 65536 + (pitched ? 4 : 0); };
  p.color_in = pitched ? 4 : 0;
  p.depth = next(p.color_in + p.color_pitch * h);
  p.color_out = in_place ? p.color_in : next(p.depth + p.depth_pitch * h);
  p.bytes = (in_place ? p.depth + p.depth_pitch * h : p.color_out + p.color_pitch * h) + 4096;
  return p;
}

void put_rows(std::vector<unsigned char>& dst, std::size_t offset, std::size_t pitch, const void* src,
              std::size_t row, int h) {
  for (int y = 0; y < h; ++y)
    std::memcpy(dst.data() + offset + std::size_t(y) * pitch, static_cast<const unsigned char*>(src) + y * row, row);
}
void get_rows(const std::vector<unsigned char>& src, std::size_t offset, std::size_t pitch, void* dst,
              std::size_t row, int h) {
  for (int y = 0; y < h; ++y)
    std::memcpy(static_cast<unsigned char*>(dst) + y * row, src.data() + offset + std::size_t(y) * pitch, row);
}

FogSettings interop_settings(float density) {
  FogSettings s;
  s.mode = FogMode::exp;
  s.color = {0.55f, 0.6f, 0.7f};
  s.density = density;
  return s;
}

// CUDA writes the frame, fogcl fogs it in CUDA's memory (in and out of place, packed and pitched),
// CUDA reads it back: equal to FogPass::apply on host images bit for bit, and every byte outside
// the output plane as CUDA wrote it. Both storages, 1080p and 4K.
TEST(GpuInterop, FramesInCudaMemoryEqualHostApply) {
  FOGCL_REQUIRE_CUDA_INTEROP();
  CudaSide& c = cuda_side();
  const cl_context context = runtime()->context();
  const cl_device_id device = runtime()->device();
  FogPass& pass = shared_pass();
  std::size_t worst_floats = 0;
  int cases = 0;
  for (const auto& [w, h] : {std::pair{1920, 1080}, std::pair{3840, 2160}})
    for (const ColorFormat format : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
      const TestFrame t = make_test_frame(w, h, false, format, std::uint32_t(w + int(format)));
      const FogSettings settings = interop_settings(0.02f);
      ColorImage expected;
      pass.apply(t.color, t.depth, expected, t.params, settings);
      const std::size_t color_row = std::size_t(w) * bytes_per_pixel(format);
      for (const bool pitched : {false, true})
        for (const bool in_place : {true, false}) {
          SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h) + " " + to_string(format) +
                       (pitched ? " pitched" : " packed") + (in_place ? " in place" : " out of place"));
          const Placement p = place(w, h, format, pitched, in_place);
          cuda::ExportableAllocation alloc;
          ASSERT_EQ(alloc.create(c.cu, c.device, p.bytes), "");
          std::vector<unsigned char> bytes(alloc.size);
          for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<unsigned char>(i * 7 + 3);
          put_rows(bytes, p.color_in, p.color_pitch, t.color.data(), color_row, h);
          put_rows(bytes, p.depth, p.depth_pitch, t.depth.data(), std::size_t(w) * 4, h);
          CU_OK(c.cu.cuMemcpyHtoD(alloc.ptr, bytes.data(), bytes.size()));

          const int fd = alloc.export_fd();
          ASSERT_GE(fd, 0);
          ExternalMemory memory(context, device, fd, alloc.size);
          ExternalFrameLayout layout;
          layout.width = w;
          layout.height = h;
          layout.format = format;
          layout.color_in = {&memory, p.color_in, pitched ? p.color_pitch : 0};
          layout.depth = {&memory, p.depth, pitched ? p.depth_pitch : 0};
          if (!in_place) layout.color_out = {&memory, p.color_out, pitched ? p.color_pitch : 0};
          ExternalFrame frame(context, device, layout);
          EXPECT_EQ(frame.zero_copy(), !pitched);
          cl_event done = frame.enqueue(pass, runtime()->queue(), t.params, settings);
          ASSERT_EQ(clWaitForEvents(1, &done), CL_SUCCESS);
          clReleaseEvent(done);

          std::vector<unsigned char> back(alloc.size);
          CU_OK(c.cu.cuMemcpyDtoH(back.data(), alloc.ptr, back.size()));
          ColorImage got(w, h, format);
          get_rows(back, p.color_out, p.color_pitch, got.data(), color_row, h);
          const std::size_t differing = differing_floats(got, expected);
          worst_floats = std::max(worst_floats, differing);
          EXPECT_EQ(std::memcmp(got.data(), expected.data(), expected.size_bytes()), 0)
              << differing << " differing values";
          // Everything but the output plane's rows is untouched (padding, depth, the input).
          if (in_place) put_rows(back, p.color_in, p.color_pitch, t.color.data(), color_row, h);  // as uploaded
          std::size_t changed = 0;
          for (std::size_t i = 0; i < back.size(); ++i) {
            const bool in_out_plane = !in_place && i >= p.color_out && i < p.color_out + p.color_pitch * h &&
                                      (i - p.color_out) % p.color_pitch < color_row;
            if (!in_out_plane && back[i] != bytes[i]) ++changed;
          }
          EXPECT_EQ(changed, 0u) << "bytes outside the output plane changed";
          ++cases;
        }
    }
  std::printf("[ info ] %d frames through CUDA memory; worst: %zu values differing from FogPass::apply\n", cases,
              worst_floats);
}

// The layout's rules, each refused with an error naming the plane.
TEST(GpuInterop, LayoutErrorsNameThePlane) {
  FOGCL_REQUIRE_CUDA_INTEROP();
  CudaSide& c = cuda_side();
  cuda::ExportableAllocation alloc;
  ASSERT_EQ(alloc.create(c.cu, c.device, 64 * 64 * 16 * 2 + 64 * 64 * 4), "");
  ExternalMemory memory(runtime()->context(), runtime()->device(), alloc.export_fd(), alloc.size);
  auto error = [&](auto edit) {
    ExternalFrameLayout l;
    l.width = 64;
    l.height = 64;
    l.color_in = {&memory, 0, 0};
    l.depth = {&memory, 65536, 0};
    edit(l);
    return error_of([&] { ExternalFrame(runtime()->context(), runtime()->device(), l); });
  };
  const std::string beyond = error([&](ExternalFrameLayout& l) { l.depth.offset = alloc.size - 100; });
  EXPECT_NE(beyond.find("depth ends at byte"), std::string::npos) << beyond;
  const std::string pitch = error([&](ExternalFrameLayout& l) { l.color_in.row_pitch = 64 * 16 - 16; });
  EXPECT_NE(pitch.find("color_in.row_pitch"), std::string::npos) << pitch;
  const std::string overlap = error([&](ExternalFrameLayout& l) { l.color_out = {&memory, 64 * 16, 0}; });
  EXPECT_NE(overlap.find("color_out overlaps color_in"), std::string::npos) << overlap;
  const std::string null_memory = error([&](ExternalFrameLayout& l) { l.depth.memory = nullptr; });
  EXPECT_NE(null_memory.find("depth.memory is null"), std::string::npos) << null_memory;
  ExternalFrameLayout valid;
  valid.width = 64;
  valid.height = 64;
  valid.color_in = {&memory, 0, 0};
  valid.depth = {&memory, 65536, 0};
  EXPECT_NO_THROW(ExternalFrame(runtime()->context(), runtime()->device(), valid));
  const std::string no_export = error_of([&] { ExternalSemaphore::exportable(runtime()->context(), runtime()->device()); });
  std::printf("[ info ] %s\n[ info ] %s\n[ info ] exportable semaphore: %s\n", beyond.c_str(), overlap.c_str(),
              no_export.empty() ? "made" : no_export.c_str());
}

// 100 consecutive frames, with no host wait between the producer and fogcl: per frame CUDA copies
// one of four frames into the shared memory and signals "ready"; fogcl waits for it on the GPU,
// fogs the frame in place with that frame's density and signals "done"; CUDA waits for it and
// copies the result aside. The host only enqueues; at the end each result equals FogPass::apply.
TEST(GpuInterop, HundredFramesWithSemaphoresNoHostWait) {
  FOGCL_REQUIRE_CUDA_INTEROP();
  CudaSide& c = cuda_side();
  const cl_context context = runtime()->context();
  const cl_device_id device = runtime()->device();
  if (!external_support(device).imports_semaphore(ExternalHandle::opaque_fd))
    GTEST_SKIP() << device_name(device) << " imports no opaque-fd semaphores: " << external_support(device).describe();
  vk::ExportableSemaphores vulkan;
  std::string why;
  if (!vulkan.open(c.uuid, why)) GTEST_SKIP() << "no semaphore to share: " << why;
  const int ready = vulkan.create(), done = vulkan.create();
  ASSERT_GE(ready, 0);
  ASSERT_GE(done, 0);
  const ExternalSemaphore cl_ready = ExternalSemaphore::import_fd(context, device, vulkan.export_fd(ready));
  const ExternalSemaphore cl_done = ExternalSemaphore::import_fd(context, device, vulkan.export_fd(done));
  cuda::CUexternalSemaphore cu_ready = nullptr, cu_done = nullptr;
  cuda::CUDA_EXTERNAL_SEMAPHORE_HANDLE_DESC desc{};
  desc.type = cuda::CU_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD;
  desc.handle.fd = vulkan.export_fd(ready);
  CU_OK(c.cu.cuImportExternalSemaphore(&cu_ready, &desc));
  desc.handle.fd = vulkan.export_fd(done);
  CU_OK(c.cu.cuImportExternalSemaphore(&cu_done, &desc));

  FogPass& pass = shared_pass();
  for (const ColorFormat format : {ColorFormat::rgba16f, ColorFormat::rgba32f}) {
    SCOPED_TRACE(to_string(format));
    const int w = 1920, h = 1080, sources = 4, frames = 100;
    const std::size_t color_bytes = color_buffer_bytes(w, h, format), depth_bytes = depth_buffer_bytes(w, h);
    std::vector<TestFrame> src;
    std::vector<cuda::CUdeviceptr> src_color(sources), src_depth(sources), results(frames);
    for (int i = 0; i < sources; ++i) {
      src.push_back(make_test_frame(w, h, false, format, std::uint32_t(100 + i)));
      CU_OK(c.cu.cuMemAlloc(&src_color[i], color_bytes));
      CU_OK(c.cu.cuMemAlloc(&src_depth[i], depth_bytes));
      CU_OK(c.cu.cuMemcpyHtoD(src_color[i], src.back().color.data(), color_bytes));
      CU_OK(c.cu.cuMemcpyHtoD(src_depth[i], src.back().depth.data(), depth_bytes));
    }
    for (auto& r : results) CU_OK(c.cu.cuMemAlloc(&r, color_bytes));
    cuda::ExportableAllocation shared;
    const std::size_t depth_at = (color_bytes + 65535) / 65536 * 65536;
    ASSERT_EQ(shared.create(c.cu, c.device, depth_at + depth_bytes), "");
    ExternalMemory memory(context, device, shared.export_fd(), shared.size);
    ExternalFrameLayout layout;
    layout.width = w;
    layout.height = h;
    layout.format = format;
    layout.color_in = {&memory, 0, 0};
    layout.depth = {&memory, depth_at, 0};
    ExternalFrame frame(context, device, layout);
    auto settings_of = [](int i) { return interop_settings(0.005f + 0.0004f * float(i)); };
    pass.prepare(settings_of(0), src[0].params, format);
    cuda::CUstream stream = nullptr;
    CU_OK(c.cu.cuStreamCreate(&stream, cuda::CU_STREAM_NON_BLOCKING));
    const ExternalSync sync{{&cl_ready}, {&cl_done}, {}};
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < frames; ++i) {
      const int k = i % sources;
      cuda::CUDA_EXTERNAL_SEMAPHORE_SIGNAL_PARAMS signal{};
      cuda::CUDA_EXTERNAL_SEMAPHORE_WAIT_PARAMS wait{};
      CU_OK(c.cu.cuMemcpyDtoDAsync(shared.ptr, src_color[k], color_bytes, stream));
      CU_OK(c.cu.cuMemcpyDtoDAsync(shared.ptr + depth_at, src_depth[k], depth_bytes, stream));
      CU_OK(c.cu.cuSignalExternalSemaphoresAsync(&cu_ready, &signal, 1, stream));
      clReleaseEvent(frame.enqueue(pass, runtime()->queue(), src[k].params, settings_of(i), sync));
      CU_OK(c.cu.cuWaitExternalSemaphoresAsync(&cu_done, &wait, 1, stream));
      CU_OK(c.cu.cuMemcpyDtoDAsync(results[i], shared.ptr, color_bytes, stream));
    }
    const double enqueue_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    CU_OK(c.cu.cuStreamSynchronize(stream));
    const double total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ASSERT_EQ(clFinish(runtime()->queue()), CL_SUCCESS);
    int wrong_frames = 0;
    std::size_t worst = 0;
    for (int i = 0; i < frames; ++i) {
      ColorImage got(w, h, format), expected;
      CU_OK(c.cu.cuMemcpyDtoH(got.data(), results[i], color_bytes));
      pass.apply(src[i % sources].color, src[i % sources].depth, expected, src[i % sources].params, settings_of(i));
      if (std::memcmp(got.data(), expected.data(), color_bytes) != 0) {
        ++wrong_frames;
        worst = std::max(worst, differing_floats(got, expected));
      }
    }
    EXPECT_EQ(wrong_frames, 0) << "worst frame: " << worst << " differing values";
    std::printf("[ info ] %s: %d frames, host enqueued them in %.1f ms, all done after %.1f ms; %d frames differ "
                "from FogPass::apply (worst %zu values)\n",
                to_string(format), frames, enqueue_ms, total_ms, wrong_frames, worst);
    c.cu.cuStreamDestroy(stream);
    for (int i = 0; i < sources; ++i) {
      c.cu.cuMemFree(src_color[i]);
      c.cu.cuMemFree(src_depth[i]);
    }
    for (auto r : results) c.cu.cuMemFree(r);
  }
  c.cu.cuDestroyExternalSemaphore(cu_ready);
  c.cu.cuDestroyExternalSemaphore(cu_done);
}

// A pass that fails after fogcl has waited for "ready" (here: a variant never prepared) still
// releases the memory and signals "done", so the producer does not wait forever; the frame keeps
// its unfogged pixels.
TEST(GpuInterop, AFailingPassStillSignalsDone) {
  FOGCL_REQUIRE_CUDA_INTEROP();
  CudaSide& c = cuda_side();
  const cl_context context = runtime()->context();
  const cl_device_id device = runtime()->device();
  vk::ExportableSemaphores vulkan;
  std::string why;
  if (!external_support(device).imports_semaphore(ExternalHandle::opaque_fd) || !vulkan.open(c.uuid, why))
    GTEST_SKIP() << "no semaphore to share: " << (why.empty() ? external_support(device).describe() : why);
  const int ready = vulkan.create(), done = vulkan.create();
  const ExternalSemaphore cl_ready = ExternalSemaphore::import_fd(context, device, vulkan.export_fd(ready));
  const ExternalSemaphore cl_done = ExternalSemaphore::import_fd(context, device, vulkan.export_fd(done));
  cuda::CUexternalSemaphore cu_ready = nullptr, cu_done = nullptr;
  cuda::CUDA_EXTERNAL_SEMAPHORE_HANDLE_DESC desc{};
  desc.type = cuda::CU_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD;
  desc.handle.fd = vulkan.export_fd(ready);
  CU_OK(c.cu.cuImportExternalSemaphore(&cu_ready, &desc));
  desc.handle.fd = vulkan.export_fd(done);
  CU_OK(c.cu.cuImportExternalSemaphore(&cu_done, &desc));
  const TestFrame t = make_test_frame(320, 180, false, ColorFormat::rgba32f, 7);
  const std::size_t color_bytes = t.color.size_bytes(), depth_at = (color_bytes + 65535) / 65536 * 65536;
  cuda::ExportableAllocation alloc;
  ASSERT_EQ(alloc.create(c.cu, c.device, depth_at + t.depth.size_bytes()), "");
  CU_OK(c.cu.cuMemcpyHtoD(alloc.ptr, t.color.data(), color_bytes));
  CU_OK(c.cu.cuMemcpyHtoD(alloc.ptr + depth_at, t.depth.data(), t.depth.size_bytes()));
  ExternalMemory memory(context, device, alloc.export_fd(), alloc.size);
  ExternalFrameLayout layout;
  layout.width = 320;
  layout.height = 180;
  layout.color_in = {&memory, 0, 0};
  layout.depth = {&memory, depth_at, 0};
  ExternalFrame frame(context, device, layout);
  FogPass unprepared(context, device);  // its own cache: nothing built
  cuda::CUstream stream = nullptr;
  CU_OK(c.cu.cuStreamCreate(&stream, cuda::CU_STREAM_NON_BLOCKING));
  cuda::CUDA_EXTERNAL_SEMAPHORE_SIGNAL_PARAMS signal{};
  cuda::CUDA_EXTERNAL_SEMAPHORE_WAIT_PARAMS wait{};
  CU_OK(c.cu.cuSignalExternalSemaphoresAsync(&cu_ready, &signal, 1, stream));
  const std::string error = error_of(
      [&] { frame.enqueue(unprepared, runtime()->queue(), t.params, interop_settings(0.02f), {{&cl_ready}, {&cl_done}, {}}); });
  EXPECT_NE(error.find("is not prepared"), std::string::npos) << error;
  CU_OK(c.cu.cuWaitExternalSemaphoresAsync(&cu_done, &wait, 1, stream));
  cuda::CUresult state = 600;
  const auto start = std::chrono::steady_clock::now();
  while ((state = c.cu.cuStreamQuery(stream)) != cuda::CUDA_SUCCESS &&
         std::chrono::steady_clock::now() - start < std::chrono::seconds(10))
    usleep(1000);
  ASSERT_EQ(state, cuda::CUDA_SUCCESS) << "CUDA still waits for \"done\" 10 s after the failed pass";
  ColorImage back(320, 180, ColorFormat::rgba32f);
  CU_OK(c.cu.cuMemcpyDtoH(back.data(), alloc.ptr, color_bytes));
  EXPECT_EQ(std::memcmp(back.data(), t.color.data(), color_bytes), 0) << "the failed frame changed";
  std::printf("[ info ] failed pass: \"%s\"; \"done\" reached CUDA after %.2f ms\n", error.c_str(),
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  c.cu.cuStreamDestroy(stream);
  c.cu.cuDestroyExternalSemaphore(cu_ready);
  c.cu.cuDestroyExternalSemaphore(cu_done);
}

// The fog volumes on a frame in CUDA's memory, in place, against VolumePass::apply on host images
// (which culls with the depth image's range, the external frame with none: the same march, up to
// the variant's culling, hence a budget rather than bits).
TEST(GpuInterop, VolumePassInCudaMemoryMatchesHostApply) {
  FOGCL_REQUIRE_CUDA_INTEROP();
  CudaSide& c = cuda_side();
  const VolumeTestScene t = volume_test_scene(960, 540);
  const int w = t.frame.color.width(), h = t.frame.color.height();
  VolumeSettings settings;
  settings.steps = 48;
  VolumePass pass(*runtime(), shared_pass().program_cache());
  ColorImage expected;
  pass.apply(t.frame.color, t.frame.depth, expected, t.frame.params, t.scene, settings);
  const std::size_t color_bytes = t.frame.color.size_bytes(), depth_at = (color_bytes + 65535) / 65536 * 65536;
  cuda::ExportableAllocation alloc;
  ASSERT_EQ(alloc.create(c.cu, c.device, depth_at + t.frame.depth.size_bytes()), "");
  CU_OK(c.cu.cuMemcpyHtoD(alloc.ptr, t.frame.color.data(), color_bytes));
  CU_OK(c.cu.cuMemcpyHtoD(alloc.ptr + depth_at, t.frame.depth.data(), t.frame.depth.size_bytes()));
  ExternalMemory memory(runtime()->context(), runtime()->device(), alloc.export_fd(), alloc.size);
  ExternalFrameLayout layout;
  layout.width = w;
  layout.height = h;
  layout.format = t.frame.color.format();
  layout.color_in = {&memory, 0, 0};
  layout.depth = {&memory, depth_at, 0};
  ExternalFrame frame(runtime()->context(), runtime()->device(), layout);
  pass.prepare(t.frame.params, t.scene, settings, layout.format);
  cl_event done = frame.enqueue(pass, runtime()->queue(), t.frame.params, t.scene, settings);
  ASSERT_EQ(clWaitForEvents(1, &done), CL_SUCCESS);
  clReleaseEvent(done);
  ColorImage got(w, h, layout.format);
  CU_OK(c.cu.cuMemcpyDtoH(got.data(), alloc.ptr, color_bytes));
  double worst = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec4 d = glm::abs(got.pixel(x, y) - expected.pixel(x, y));
      worst = std::max({worst, double(d.r), double(d.g), double(d.b), double(d.a)});
    }
  EXPECT_LE(worst, 1e-5);
  std::printf("[ info ] volumes %dx%d in CUDA memory: %zu values differ from VolumePass::apply, worst %.3g\n", w, h,
              differing_floats(got, expected), worst);
}

// examples/cuda_interop.cpp, as an integrator would run it: exit status 0 (its frame equal to
// FogPass::apply's).
TEST(GpuInterop, CudaInteropExampleRuns) {
  FOGCL_REQUIRE_CUDA_INTEROP();
  const char* bundled = std::getenv("FOGCL_TEST_CUDA_INTEROP");  // scripts/gpu-run.sh's bundle
  const std::string cmd = std::string(bundled != nullptr ? bundled : FOGCL_CUDA_INTEROP_PATH) + " 2>&1";
  restore_start_opencl_env();  // the loader's environment the suite started with, as the CLI's runs
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
  const int status = pclose(p);
  EXPECT_EQ(status, 0) << out;
  std::printf("%s", out.c_str());
}

// examples/vulkan_exporter.cpp, as an integrator would run it, on every machine: exit status 0 (its
// frame equal to FogPass::apply's) where an OpenCL device imports opaque-fd memory and a Vulkan
// device on the same GPU exports it; elsewhere (CI's PoCL imports none) the example exits 77 and
// says why, which is a skip here, and any other status a failure.
TEST(ExternalInterop, VulkanExporterExampleRuns) {
  FOGCL_REQUIRE_DEVICE();
#ifndef FOGCL_VULKAN_EXPORTER_PATH
  GTEST_SKIP() << "built without the Vulkan headers and loader (libvulkan-dev): no vulkan_exporter";
#else
  const char* bundled = std::getenv("FOGCL_TEST_VULKAN_EXPORTER");  // scripts/gpu-run.sh's bundle
  const std::string cmd = std::string(bundled != nullptr ? bundled : FOGCL_VULKAN_EXPORTER_PATH) + " 2>&1";
  restore_start_opencl_env();
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
  const int status = pclose(p);
  std::printf("%s", out.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << "vulkan_exporter did not exit (status " << status << "):\n" << out;
  if (WEXITSTATUS(status) == 77) GTEST_SKIP() << out;
  EXPECT_EQ(WEXITSTATUS(status), 0) << out;
  EXPECT_NE(out.find("equal bit for bit"), std::string::npos) << out;
#endif
}

}  // namespace
}  // namespace fogcl::test
