// The machine's own copy of a pass's bytes, the ceiling every "vs copy" ratio of the bench divides
// by (bench/fog_bench.cpp): the same bytes copied on the same number of threads in several ways,
// the fastest of them the ceiling. A cache-resident frame (1080p on a 480 MiB L3) copies fastest
// with ordinary stores, a frame larger than the cache with streaming (non-temporal) stores, and
// glibc's memcpy picks its own store kind by size (non-temporal above about 3/4 of the L3 a thread
// may use): no single copy is the ceiling on every machine. Built with -O3 -march=native.
#pragma once

#include <cstddef>
#include <functional>

namespace fogcl::bench {

enum class CopyKind {
  memcpy,  // glibc's std::memcpy
  loop,    // a loop of ordinary full-vector loads and stores (512-bit with AVX-512, else 256-bit)
  stream,  // the same loads, non-temporal stores (the destination's lines never read), one sfence
};

const char* to_string(CopyKind kind);

// Copies n bytes from src to dst (not overlapping) on the calling thread, the kind's way.
void copy_span(CopyKind kind, void* dst, const void* src, std::size_t n);

// Runs part(t) for t = 0 .. threads - 1, part(0) on the calling thread and the others on a pool of
// threads kept across calls (woken by a condition variable, asleep between calls so that they take
// no time from the pass measured after them), and returns when every part has finished.
void run_parts(int threads, const std::function<void(int)>& part);

}  // namespace fogcl::bench
