/* fog_cpu_avx512.h — x86 AVX-512 target builtins of the CPU devices' path (FOG_VECTOR_WIDTH 16),
 * for PoCL compiling for such a CPU. Each has a portable OpenCL C counterpart that writes the same
 * bytes (CpuCodegen::target_intrinsics = false defines FOG_PORTABLE; tests/cpu_block_paths_test
 * and tests/kernel_factor_bits_test compare the two). Included by deferred_fog.cl before the
 * float16 instance of fog_math.h, whose exp2 hooks are defined here; fog_cpu_blocks.h uses the
 * rest. Also what both CPU paths (deferred_fog.cl, volume_composite.cl) share on any target:
 * FOG_SHUFFLE, the constant-mask shuffle, and the streaming stores (FOG_STREAMS, FOG_STREAM_OR). */

/* shuffle2(a, b, (uint16)(indices)) with literal indices, as one permute. clang's
 * __builtin_shufflevector is a language builtin (no target needed): PoCL 5.0 (Ubuntu 24.04)
 * lowers OpenCL's shuffle / shuffle2 to a call of an out-of-line library routine that reads the
 * mask at run time, four of them per 16-pixel block, which made the deferred kernel 5-12x slower
 * on the 16-core Xeon (docs/performance.md#the-deferred-block-path, "Constant shuffles"); PoCL 3.1
 * inlined them. */
#ifdef __clang__
#define FOG_SHUFFLE(a, b, ...) __builtin_shufflevector((a), (b), __VA_ARGS__)
#else
#define FOG_SHUFFLE(a, b, ...) shuffle2((a), (b), (uint16)(__VA_ARGS__))
#endif

/* Streaming stores (FOG_STREAMING_MIN_PIXELS, docs/DESIGN.md §3). FOG_STREAMS(width, height):
 * whether a frame's RGBA32F output is written with non-temporal stores. FOG_STREAM_OR(bits, p,
 * stream, ordinary): the 16 words `bits` (uint16) go to p (global uint*) with a non-temporal store
 * where stream is set and p is 64-byte aligned, else the statement `ordinary` stores them: no
 * read-for-ownership of lines this pass never reads back. The driver's completion signalling
 * (locked instructions, which drain the write-combining buffers) orders them for the host. A
 * macro, not a function: with the store behind a helper's return value, PoCL 3.1's LLVM 15 kept
 * 3 of a kernel's 27 non-temporal stores (merged with the ordinary ones) and the composite's none. */
#ifdef FOG_STREAMING_MIN_PIXELS
#define FOG_STREAMS(width, height) ((long)(width) * (long)(height) >= (long)FOG_STREAMING_MIN_PIXELS)
#else
#define FOG_STREAMS(width, height) 0
#endif
#if defined(FOG_STREAMING_MIN_PIXELS) && defined(__clang__)
#define FOG_STREAM_OR(bits, p, stream, ordinary)                 \
  do {                                                           \
    if ((stream) && (((size_t)(p)) & 63) == 0)                   \
      __builtin_nontemporal_store((bits), (global uint16*)(p));  \
    else {                                                       \
      ordinary;                                                  \
    }                                                            \
  } while (0)
#else
#define FOG_STREAM_OR(bits, p, stream, ordinary) \
  do {                                           \
    ordinary;                                    \
  } while (0)
#endif

#if defined(__clang__) && defined(__AVX512F__) && !defined(FOG_PORTABLE)
#define FOG_AVX512 1
typedef float fog_v16f __attribute__((__vector_size__(64)));
typedef short fog_v16h __attribute__((__vector_size__(32), aligned(2)));

/* Lanes rounded to an integer by one vrndscaleps (PoCL's ceil and floor are 12-instruction
 * routines); imm: 0x0a up, 0x09 down (no precision exception), a literal. */
#define FOG_RNDSCALE_AVX512(x, imm)                                                                   \
  __builtin_bit_cast(float16, __builtin_ia32_rndscaleps_mask(__builtin_bit_cast(fog_v16f, (x)), (imm), \
                                                             (fog_v16f){}, (ushort)0xffff, 4 /* current rounding */))
static inline float16 fog_ceil_avx512(float16 x) { return FOG_RNDSCALE_AVX512(x, 0x0a); }
static inline float16 fog_floor_avx512(float16 x) { return FOG_RNDSCALE_AVX512(x, 0x09); }

/* p * 2^n for an integral n, rounded once: one vscalefps (height fog's e^x, whose n reaches -150
 * and 129, needs two multiplies otherwise). */
static inline float16 fog_scale2_avx512(float16 p, float16 n) {
  return __builtin_bit_cast(float16, __builtin_ia32_scalefps512_mask(
      __builtin_bit_cast(fog_v16f, p), __builtin_bit_cast(fog_v16f, n), (fog_v16f){}, (ushort)0xffff,
      4 /* current rounding */));
}

/* p * 2^n where x >= -126, else 0: one vscalefps under a zero mask. n is an integer in
 * [-126, 0] wherever x >= -126, so p * 2^n is exact there, as the portable path's multiply by the
 * bits of 2^n is; the masked lanes may hold anything (x = -inf makes them NaN). */
static inline float16 fog_exp2_ldexp_avx512(float16 p, float16 n, float16 x) {
  const ushort in_range = __builtin_ia32_cmpps512_mask(
      __builtin_bit_cast(fog_v16f, x), __builtin_bit_cast(fog_v16f, (float16)-126.0f),
      0x1d /* _CMP_GE_OQ */, (ushort)0xffff, 4 /* current rounding */);
  return __builtin_bit_cast(float16, __builtin_ia32_scalefps512_mask(
      __builtin_bit_cast(fog_v16f, p), __builtin_bit_cast(fog_v16f, n), (fog_v16f){}, in_range,
      4 /* current rounding */));
}
#endif
