/* Preloaded into one Slurm task's fogcl by run_slurm_test.sh: opening the file whose path ends in
 * $FOGCL_GATE_SUFFIX blocks forever, so the task stops after its earlier frames, deterministically,
 * until the test kills it. (fogcl refuses a FIFO as an input before it reads any frame, so the gate
 * cannot be a FIFO nobody writes.) Every other open goes to the C library. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void hold_if_gate(const char* path) {
  const char* suffix = getenv("FOGCL_GATE_SUFFIX");
  if (path == NULL || suffix == NULL || *suffix == '\0') return;
  const size_t n = strlen(path), m = strlen(suffix);
  if (n >= m && strcmp(path + n - m, suffix) == 0)
    for (;;) pause();
}

#define FORWARD_OPEN(name)                                                   \
  int name(const char* path, int flags, ...) {                               \
    mode_t mode = 0;                                                         \
    if (flags & (O_CREAT | O_TMPFILE)) {                                     \
      va_list ap;                                                            \
      va_start(ap, flags);                                                   \
      mode = va_arg(ap, mode_t);                                             \
      va_end(ap);                                                            \
    }                                                                        \
    hold_if_gate(path);                                                      \
    int (*next)(const char*, int, ...) = dlsym(RTLD_NEXT, #name);            \
    return next(path, flags, mode);                                          \
  }
FORWARD_OPEN(open)
FORWARD_OPEN(open64)

#define FORWARD_OPENAT(name)                                                 \
  int name(int dir, const char* path, int flags, ...) {                      \
    mode_t mode = 0;                                                         \
    if (flags & (O_CREAT | O_TMPFILE)) {                                     \
      va_list ap;                                                            \
      va_start(ap, flags);                                                   \
      mode = va_arg(ap, mode_t);                                             \
      va_end(ap);                                                            \
    }                                                                        \
    hold_if_gate(path);                                                      \
    int (*next)(int, const char*, int, ...) = dlsym(RTLD_NEXT, #name);       \
    return next(dir, path, flags, mode);                                     \
  }
FORWARD_OPENAT(openat)
FORWARD_OPENAT(openat64)

#define FORWARD_FOPEN(name)                                                  \
  FILE* name(const char* path, const char* mode) {                           \
    hold_if_gate(path);                                                      \
    FILE* (*next)(const char*, const char*) = dlsym(RTLD_NEXT, #name);       \
    return next(path, mode);                                                 \
  }
FORWARD_FOPEN(fopen)
FORWARD_FOPEN(fopen64)
