/* Preloaded into a fogcl (LD_PRELOAD) to hold it at a chosen call, deterministically, until a test
 * has done what it must while that call is in progress:
 *
 *   FOGCL_GATE_SUFFIX  a path ending in this is held (either path of a rename or link).
 *   FOGCL_GATE_CALLS   the calls that hold, comma-separated: of open, open64, openat, openat64,
 *                      fopen, fopen64, rename, renameat, renameat2, linkat. Default: the opens.
 *   FOGCL_GATE_FD      a descriptor the gate writes lines to: "held CALL PATH" once it holds, and
 *                      "handled SIGNO" each time one of the program's signal handlers has returned.
 *                      With it set, the program's handlers (sigaction) run wrapped so that the
 *                      gate sees them.
 *   FOGCL_GATE_RELEASE how many of the program's signal handlers must have returned before the
 *                      held call proceeds (needs FOGCL_GATE_FD), so it sees what they did. Unset or
 *                      0: the call never proceeds; the process stays there until it is killed.
 *
 * The Slurm test (tests/slurm/run_slurm_test.sh) holds the open of an input: fogcl refuses a FIFO as
 * an input before it reads any frame, so the gate cannot be a FIFO nobody writes. The signal tests
 * (tests/cli_safety_test.cpp, tests/sequence_test.cpp) hold the rename or link that names a
 * finished output, so each signal lands while that write is provably in progress. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int handled = 0;         /* the program's handlers that have returned, since the start */
static int wake[2] = {-1, -1};  /* a byte per handled signal, for the held call to wait on */

/* Read before any handler is wrapped (sigaction below), so a handler never calls getenv. */
static int announce_fd(void) {
  static int fd = -2;
  if (fd == -2) {
    const char* value = getenv("FOGCL_GATE_FD");
    fd = value != NULL && *value != '\0' ? atoi(value) : -1;
  }
  return fd;
}

/* Async-signal-safe: write(2) only. */
static void announce(const char* what, const char* detail) {
  const int fd = announce_fd();
  if (fd < 0) return;
  char line[4096];
  size_t n = 0;
  for (const char* s = what; *s != '\0' && n < sizeof line - 2; ++s) line[n++] = *s;
  line[n++] = ' ';
  for (const char* s = detail; *s != '\0' && n < sizeof line - 1; ++s) line[n++] = *s;
  line[n++] = '\n';
  ssize_t w;
  do w = write(fd, line, n);
  while (w < 0 && errno == EINTR);
}

static int gated_call(const char* call) {
  const char* calls = getenv("FOGCL_GATE_CALLS");
  if (calls == NULL || *calls == '\0') calls = "open,open64,openat,openat64,fopen,fopen64";
  const size_t m = strlen(call);
  for (const char* at = calls; *at != '\0';) {
    const char* end = strchr(at, ',');
    const size_t n = end != NULL ? (size_t)(end - at) : strlen(at);
    if (n == m && strncmp(at, call, m) == 0) return 1;
    if (end == NULL) break;
    at = end + 1;
  }
  return 0;
}

static int gated_path(const char* path) {
  const char* suffix = getenv("FOGCL_GATE_SUFFIX");
  if (path == NULL || suffix == NULL || *suffix == '\0') return 0;
  const size_t n = strlen(path), m = strlen(suffix);
  return n >= m && strcmp(path + n - m, suffix) == 0;
}

/* Holds the calling thread if `call` on `path` (or `other`) is gated: until FOGCL_GATE_RELEASE
 * signals have been handled, or for ever. */
static void hold_if_gate(const char* call, const char* path, const char* other) {
  if (!gated_call(call) || !(gated_path(path) || gated_path(other))) return;
  const char* release = getenv("FOGCL_GATE_RELEASE");
  const int after = release != NULL ? atoi(release) : 0;
  if (wake[0] < 0 && pipe2(wake, O_CLOEXEC) != 0) wake[0] = wake[1] = -1;
  char detail[4096];
  snprintf(detail, sizeof detail, "%s %s", call, gated_path(path) ? path : other);
  announce("held", detail);
  if (after <= 0 || wake[0] < 0)
    for (;;) pause();
  while (__atomic_load_n(&handled, __ATOMIC_SEQ_CST) < after) {
    char byte;
    if (read(wake[0], &byte, 1) < 0 && errno != EINTR) for (;;) pause();
  }
}

/* ---- The program's signal handlers, wrapped (only with FOGCL_GATE_FD) ---------------------------- */

static struct sigaction programs[NSIG];  /* the action the program asked for, per signal */
static int wrapped[NSIG];

static void on_signal(int signo, siginfo_t* info, void* context) {
  const int saved_errno = errno;
  const struct sigaction* a = &programs[signo];
  if (a->sa_flags & SA_SIGINFO)
    a->sa_sigaction(signo, info, context);
  else if (a->sa_handler != SIG_DFL && a->sa_handler != SIG_IGN)
    a->sa_handler(signo);
  __atomic_add_fetch(&handled, 1, __ATOMIC_SEQ_CST);
  char number[16], *digits = number + sizeof number - 1;
  *digits = '\0';
  do *--digits = (char)('0' + signo % 10);
  while ((signo /= 10) > 0);
  announce("handled", digits);
  if (wake[1] >= 0) {
    ssize_t w;
    do w = write(wake[1], "x", 1);
    while (w < 0 && errno == EINTR);
  }
  errno = saved_errno;
}

int sigaction(int signo, const struct sigaction* act, struct sigaction* old) {
  int (*next)(int, const struct sigaction*, struct sigaction*) = dlsym(RTLD_NEXT, "sigaction");
  if (announce_fd() < 0 || signo <= 0 || signo >= NSIG) return next(signo, act, old);
  const struct sigaction before = programs[signo];
  const int was_wrapped = wrapped[signo];
  int result;
  const int handler = act != NULL && ((act->sa_flags & SA_SIGINFO) ||
                                      (act->sa_handler != SIG_DFL && act->sa_handler != SIG_IGN));
  if (handler) {
    struct sigaction mine = *act;
    mine.sa_flags |= SA_SIGINFO;
    mine.sa_sigaction = on_signal;
    programs[signo] = *act;
    result = next(signo, &mine, old);
    if (result == 0) wrapped[signo] = 1;
    else programs[signo] = before;
  } else {
    result = next(signo, act, old);
    if (result == 0 && act != NULL) wrapped[signo] = 0;
  }
  if (result == 0 && old != NULL && was_wrapped) *old = before;
  return result;
}

/* ---- The gated calls ------------------------------------------------------------------------------ */

#define FORWARD_OPEN(name)                                                   \
  int name(const char* path, int flags, ...) {                               \
    mode_t mode = 0;                                                         \
    if (flags & (O_CREAT | O_TMPFILE)) {                                     \
      va_list ap;                                                            \
      va_start(ap, flags);                                                   \
      mode = va_arg(ap, mode_t);                                             \
      va_end(ap);                                                            \
    }                                                                        \
    hold_if_gate(#name, path, NULL);                                         \
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
    hold_if_gate(#name, path, NULL);                                         \
    int (*next)(int, const char*, int, ...) = dlsym(RTLD_NEXT, #name);       \
    return next(dir, path, flags, mode);                                     \
  }
FORWARD_OPENAT(openat)
FORWARD_OPENAT(openat64)

#define FORWARD_FOPEN(name)                                                  \
  FILE* name(const char* path, const char* mode) {                           \
    hold_if_gate(#name, path, NULL);                                         \
    FILE* (*next)(const char*, const char*) = dlsym(RTLD_NEXT, #name);       \
    return next(path, mode);                                                 \
  }
FORWARD_FOPEN(fopen)
FORWARD_FOPEN(fopen64)

int rename(const char* from, const char* to) {
  hold_if_gate("rename", to, from);
  int (*next)(const char*, const char*) = dlsym(RTLD_NEXT, "rename");
  return next(from, to);
}

int renameat(int from_dir, const char* from, int to_dir, const char* to) {
  hold_if_gate("renameat", to, from);
  int (*next)(int, const char*, int, const char*) = dlsym(RTLD_NEXT, "renameat");
  return next(from_dir, from, to_dir, to);
}

int renameat2(int from_dir, const char* from, int to_dir, const char* to, unsigned int flags) {
  hold_if_gate("renameat2", to, from);
  int (*next)(int, const char*, int, const char*, unsigned int) = dlsym(RTLD_NEXT, "renameat2");
  return next(from_dir, from, to_dir, to, flags);
}

int linkat(int from_dir, const char* from, int to_dir, const char* to, int flags) {
  hold_if_gate("linkat", to, from);
  int (*next)(int, const char*, int, const char*, int) = dlsym(RTLD_NEXT, "linkat");
  return next(from_dir, from, to_dir, to, flags);
}
