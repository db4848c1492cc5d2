#include "copy_peer.h"

#include <immintrin.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <thread>
#include <vector>

namespace fogcl::bench {

const char* to_string(CopyKind kind) {
  switch (kind) {
    case CopyKind::memcpy: return "memcpy";
    case CopyKind::loop: return "loop";
    case CopyKind::stream: return "stream";
  }
  return "?";
}

namespace {

#ifdef __AVX512F__
constexpr std::size_t kVector = 64;
using Vec = __m512i;
inline Vec load(const char* p) { return _mm512_loadu_si512(p); }
inline void store(char* p, Vec v) { _mm512_storeu_si512(p, v); }
inline void stream(char* p, Vec v) { _mm512_stream_si512(reinterpret_cast<Vec*>(p), v); }
#else
constexpr std::size_t kVector = 32;
using Vec = __m256i;
inline Vec load(const char* p) { return _mm256_loadu_si256(reinterpret_cast<const Vec*>(p)); }
inline void store(char* p, Vec v) { _mm256_storeu_si256(reinterpret_cast<Vec*>(p), v); }
inline void stream(char* p, Vec v) { _mm256_stream_si256(reinterpret_cast<Vec*>(p), v); }
#endif

// Four vectors a step (one cache line or two), ordinary or non-temporal stores; the destination
// aligned to the vector for the non-temporal ones (the head up to it and the tail by memcpy).
template <bool kStream>
void vector_copy(char* dst, const char* src, std::size_t n) {
  std::size_t i = 0;
  if (kStream) {
    const std::size_t head = (kVector - reinterpret_cast<std::uintptr_t>(dst) % kVector) % kVector;
    i = head < n ? head : n;
    std::memcpy(dst, src, i);
  }
  for (; i + 4 * kVector <= n; i += 4 * kVector) {
    const Vec a = load(src + i), b = load(src + i + kVector), c = load(src + i + 2 * kVector),
              d = load(src + i + 3 * kVector);
    if (kStream) {
      stream(dst + i, a);
      stream(dst + i + kVector, b);
      stream(dst + i + 2 * kVector, c);
      stream(dst + i + 3 * kVector, d);
    } else {
      store(dst + i, a);
      store(dst + i + kVector, b);
      store(dst + i + 2 * kVector, c);
      store(dst + i + 3 * kVector, d);
    }
  }
  std::memcpy(dst + i, src + i, n - i);
  if (kStream) _mm_sfence();
}

// The pool of run_parts: workers 1 .. threads - 1, each waiting for a new generation.
class Pool {
 public:
  ~Pool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      quit_ = true;
    }
    wake_.notify_all();
    for (auto& t : workers_) t.join();
  }

  void run(int threads, const std::function<void(int)>& part) {
    if (threads <= 1) return part(0);
    while (int(workers_.size()) < threads - 1) {
      const int id = int(workers_.size()) + 1;
      workers_.emplace_back([this, id] { work(id); });
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      part_ = &part;
      active_ = threads;
      pending_.store(threads - 1);
      ++generation_;
    }
    wake_.notify_all();
    part(0);
    while (pending_.load(std::memory_order_acquire) != 0) _mm_pause();
  }

 private:
  void work(int id) {
    std::uint64_t seen = 0;
    for (;;) {
      const std::function<void(int)>* part;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return quit_ || generation_ != seen; });
        if (quit_) return;
        seen = generation_;
        if (id >= active_) continue;
        part = part_;
      }
      (*part)(id);
      pending_.fetch_sub(1, std::memory_order_release);
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<std::thread> workers_;
  const std::function<void(int)>* part_ = nullptr;
  std::uint64_t generation_ = 0;
  int active_ = 0;
  bool quit_ = false;
  std::atomic<int> pending_{0};
};

}  // namespace

void copy_span(CopyKind kind, void* dst, const void* src, std::size_t n) {
  char* d = static_cast<char*>(dst);
  const char* s = static_cast<const char*>(src);
  switch (kind) {
    case CopyKind::memcpy: std::memcpy(d, s, n); return;
    case CopyKind::loop: return vector_copy<false>(d, s, n);
    case CopyKind::stream: return vector_copy<true>(d, s, n);
  }
}

void run_parts(int threads, const std::function<void(int)>& part) {
  static Pool pool;
  pool.run(threads, part);
}

}  // namespace fogcl::bench
