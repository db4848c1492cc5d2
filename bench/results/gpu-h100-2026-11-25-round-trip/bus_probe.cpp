// The bus probe of bus-probe.txt: pinned and pageable transfers, the memcpy rate by threads and a banded
// copy-and-transfer pipeline on the first GPU (else the first device), raw OpenCL.
// Build: g++ -O2 -std=c++17 -pthread bus_probe.cpp -lOpenCL
#define CL_TARGET_OPENCL_VERSION 300
#include <CL/cl.h>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>
#include <algorithm>
#include <functional>
using Clock = std::chrono::steady_clock;
static double now() { return std::chrono::duration<double, std::milli>(Clock::now().time_since_epoch()).count(); }
#define CK(x) do { cl_int e_ = (x); if (e_ != CL_SUCCESS) { printf("CL error %d at %s:%d\n", e_, __FILE__, __LINE__); exit(1);} } while (0)
cl_context ctx; cl_device_id dev; cl_command_queue q, q2;
static void pfor(int T, size_t n, const std::function<void(size_t, size_t)>& f) {
  std::vector<std::thread> ts; size_t per = (n + T - 1) / T;
  for (int t = 0; t < T; ++t) { size_t a = t * per, b = std::min(n, a + per); if (a < b) ts.emplace_back(f, a, b); }
  for (auto& t : ts) t.join();
}
static void pcopy(int T, void* d, const void* s, size_t n) {
  if (T == 1) { memcpy(d, s, n); return; }
  size_t blk = 1 << 16; size_t nb = (n + blk - 1) / blk;
  pfor(T, nb, [&](size_t a, size_t b) { size_t lo = a * blk, hi = std::min(n, b * blk); memcpy((char*)d + lo, (const char*)s + lo, hi - lo); });
}
static double med(std::vector<double> v) { std::sort(v.begin(), v.end()); return v[v.size() / 2]; }
int main() {
  cl_platform_id plats[8]; cl_uint np; CK(clGetPlatformIDs(8, plats, &np));
  cl_platform_id plat = nullptr;
  for (cl_uint i = 0; i < np; ++i) { cl_uint nd = 0; if (clGetDeviceIDs(plats[i], CL_DEVICE_TYPE_GPU, 1, &dev, &nd) == CL_SUCCESS && nd) { plat = plats[i]; break; } }
  if (!plat) { CK(clGetDeviceIDs(plats[0], CL_DEVICE_TYPE_ALL, 1, &dev, nullptr)); }
  char name[256]; clGetDeviceInfo(dev, CL_DEVICE_NAME, sizeof name, name, nullptr); printf("device: %s, host threads %u\n", name, std::thread::hardware_concurrency());
  cl_int e; ctx = clCreateContext(nullptr, 1, &dev, nullptr, nullptr, &e); CK(e);
  q = clCreateCommandQueueWithProperties(ctx, dev, nullptr, &e); CK(e);
  q2 = clCreateCommandQueueWithProperties(ctx, dev, nullptr, &e); CK(e);
  struct Sz { int w, h, bpp; const char* n; } sizes[] = {{1920, 1080, 16, "1080p f32"}, {1920, 1080, 8, "1080p f16"}, {3840, 2160, 16, "4K f32"}, {3840, 2160, 8, "4K f16"}};
  for (auto s : sizes) {
    size_t cb = size_t(s.w) * s.h * s.bpp, db = size_t(s.w) * s.h * 4, inb = cb + db;
    printf("== %s: in %.1f MB out %.1f MB\n", s.n, inb / 1e6, cb / 1e6);
    cl_mem dcol = clCreateBuffer(ctx, CL_MEM_READ_WRITE, cb, nullptr, &e); CK(e);
    cl_mem ddep = clCreateBuffer(ctx, CL_MEM_READ_WRITE, db, nullptr, &e); CK(e);
    cl_mem dout = clCreateBuffer(ctx, CL_MEM_READ_WRITE, cb, nullptr, &e); CK(e);
    cl_mem pin_in = clCreateBuffer(ctx, CL_MEM_ALLOC_HOST_PTR | CL_MEM_READ_ONLY, inb, nullptr, &e); CK(e);
    cl_mem pin_out = clCreateBuffer(ctx, CL_MEM_ALLOC_HOST_PTR | CL_MEM_WRITE_ONLY, cb, nullptr, &e); CK(e);
    char* pi = (char*)clEnqueueMapBuffer(q, pin_in, CL_TRUE, CL_MAP_WRITE, 0, inb, 0, nullptr, nullptr, &e); CK(e);
    char* po = (char*)clEnqueueMapBuffer(q, pin_out, CL_TRUE, CL_MAP_READ, 0, cb, 0, nullptr, nullptr, &e); CK(e);
    char* hc = (char*)aligned_alloc(4096, cb); char* hd = (char*)aligned_alloc(4096, db); char* ho = (char*)aligned_alloc(4096, cb);
    memset(hc, 1, cb); memset(hd, 2, db); memset(ho, 3, cb); memset(pi, 4, inb); memset(po, 5, cb);
    auto rt = [&](const char* src_c, const char* src_d, char* dst) {
      double t0 = now();
      CK(clEnqueueWriteBuffer(q, dcol, CL_FALSE, 0, cb, src_c, 0, nullptr, nullptr));
      CK(clEnqueueWriteBuffer(q, ddep, CL_FALSE, 0, db, src_d, 0, nullptr, nullptr));
      clFinish(q); double t1 = now();
      CK(clEnqueueReadBuffer(q, dout, CL_FALSE, 0, cb, dst, 0, nullptr, nullptr));
      clFinish(q); double t2 = now();
      return std::make_pair(t1 - t0, t2 - t1);
    };
    for (int kind = 0; kind < 2; ++kind) {
      std::vector<double> up, down;
      for (int r = 0; r < 7; ++r) { auto p = kind ? rt(pi, pi + cb, po) : rt(hc, hd, ho); up.push_back(p.first); down.push_back(p.second); }
      double u = med(up), d = med(down);
      printf("%s: up %.2f ms (%.1f GB/s) down %.2f ms (%.1f GB/s) total %.2f\n", kind ? "pinned  " : "pageable", u, inb / u / 1e6, d, cb / d / 1e6, u + d);
    }
    // duplex: upload on q while download on q2
    { std::vector<double> t; for (int r = 0; r < 5; ++r) { double t0 = now();
        CK(clEnqueueWriteBuffer(q, dcol, CL_FALSE, 0, cb, pi, 0, nullptr, nullptr));
        CK(clEnqueueWriteBuffer(q, ddep, CL_FALSE, 0, db, pi + cb, 0, nullptr, nullptr));
        CK(clEnqueueReadBuffer(q2, dout, CL_FALSE, 0, cb, po, 0, nullptr, nullptr));
        clFinish(q); clFinish(q2); t.push_back(now() - t0); }
      printf("duplex pinned up+down on 2 queues: %.2f ms\n", med(t)); }
    // old way: COPY_HOST_PTR create + blocking read
    { std::vector<double> t; for (int r = 0; r < 3; ++r) { double t0 = now();
        cl_mem a = clCreateBuffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, cb, hc, &e); CK(e);
        cl_mem b = clCreateBuffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, db, hd, &e); CK(e);
        cl_mem c = clCreateBuffer(ctx, CL_MEM_WRITE_ONLY, cb, nullptr, &e); CK(e);
        CK(clEnqueueCopyBuffer(q, a, c, 0, 0, cb, 0, nullptr, nullptr));
        CK(clEnqueueReadBuffer(q, c, CL_TRUE, 0, cb, ho, 0, nullptr, nullptr));
        clReleaseMemObject(a); clReleaseMemObject(b); clReleaseMemObject(c); t.push_back(now() - t0); }
      printf("old (create COPY_HOST_PTR + copy + blocking read): %.2f ms\n", med(t)); }
    // USE_HOST_PTR on pageable
    { std::vector<double> t; for (int r = 0; r < 3; ++r) { double t0 = now();
        cl_mem a = clCreateBuffer(ctx, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, cb, hc, &e); CK(e);
        CK(clEnqueueCopyBuffer(q, a, dcol, 0, 0, cb, 0, nullptr, nullptr)); clFinish(q);
        clReleaseMemObject(a); t.push_back(now() - t0); }
      printf("USE_HOST_PTR create + copy to device (color only): %.2f ms\n", med(t)); }
    // memcpy pageable->pinned with T threads
    for (int T : {1, 2, 4, 8, 16}) {
      std::vector<double> t; for (int r = 0; r < 5; ++r) { double t0 = now(); pcopy(T, pi, hc, cb); pcopy(T, pi + cb, hd, db); pcopy(T, ho, po, cb); t.push_back(now() - t0); }
      printf("memcpy in+out T=%d: %.2f ms (%.1f GB/s)\n", T, med(t), (inb + cb) / med(t) / 1e6);
    }
    // chunked pipeline: bands, T threads
    for (int bands : {4, 8, 16}) for (int T : {4, 8}) {
      std::vector<double> t;
      for (int r = 0; r < 5; ++r) {
        double t0 = now();
        size_t cband = (cb + bands - 1) / bands, dband = (db + bands - 1) / bands;
        std::vector<cl_event> ev;
        for (int b = 0; b < bands; ++b) {
          size_t co = b * cband, cn = std::min(cb, co + cband) - co; size_t dof = b * dband, dn = std::min(db, dof + dband) - dof;
          pcopy(T, pi + co, hc + co, cn); pcopy(T, pi + cb + dof, hd + dof, dn);
          CK(clEnqueueWriteBuffer(q, dcol, CL_FALSE, co, cn, pi + co, 0, nullptr, nullptr));
          CK(clEnqueueWriteBuffer(q, ddep, CL_FALSE, dof, dn, pi + cb + dof, 0, nullptr, nullptr));
        }
        for (int b = 0; b < bands; ++b) { size_t co = b * cband, cn = std::min(cb, co + cband) - co; cl_event x;
          CK(clEnqueueReadBuffer(q, dout, CL_FALSE, co, cn, po + co, 0, nullptr, &x)); ev.push_back(x); }
        clFlush(q);
        for (int b = 0; b < bands; ++b) { size_t co = b * cband, cn = std::min(cb, co + cband) - co; clWaitForEvents(1, &ev[b]); clReleaseEvent(ev[b]); pcopy(T, ho + co, po + co, cn); }
        t.push_back(now() - t0);
      }
      printf("chunked bands=%d T=%d: %.2f ms\n", bands, T, med(t));
    }
    free(hc); free(hd); free(ho);
    clEnqueueUnmapMemObject(q, pin_in, pi, 0, nullptr, nullptr); clEnqueueUnmapMemObject(q, pin_out, po, 0, nullptr, nullptr); clFinish(q);
    for (cl_mem m : {dcol, ddep, dout, pin_in, pin_out}) clReleaseMemObject(m);
  }
}
