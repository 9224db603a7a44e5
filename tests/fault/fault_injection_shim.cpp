// Fault injection for the tests (issue 24): an LD_PRELOAD library that counts a process's
// write(2), pwrite(2) and stdio fwrite(3) to regular files, rename(2)/renameat(2)/renameat2(2),
// fsync(2)/fdatasync(2) of files and of directories, and at the k-th of them either kills the process (SIGKILL, before
// the call: a power cut between two system calls) or fails that one call (ENOSPC or EIO) and lets the process go on.
// Driven by the environment:
//   BELLOWS_FAULT_AT=k           1-based; 0 or unset: never
//   BELLOWS_FAULT_MODE=kill|enospc|eio
//   BELLOWS_FAULT_COUNT=FILE     at exit, the number of calls counted (to know how many k to sweep)
//   BELLOWS_FAULT_ARMED=0|1      counted only while not "0" (a driver arms it just before the save
//                                under test; a process that does not set it is counted throughout)
// Standard output and error (fds 1 and 2) are never counted: they are the report, not the save;
// nor are files in memory (memfd: a library's scratch, e.g. the MAT export's before the safe writer
// writes it out). Only the process under test is shimmed: LD_PRELOAD is removed from its
// environment at load, so a child it starts (gnuplot) runs as it would without the shim.
#include <dlfcn.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

std::atomic<long> g_counted{0};

template <typename F>
F real(const char* name) {
  return reinterpret_cast<F>(::dlsym(RTLD_NEXT, name));
}

bool armed() {
  const char* armed = std::getenv("BELLOWS_FAULT_ARMED");
  return armed == nullptr || std::strcmp(armed, "0") != 0;
}

/// Counts one call; true when this is the call to fail (errno set), after killing when asked.
bool strike() {
  if (!armed()) return false;
  const long n = ++g_counted;
  const char* at = std::getenv("BELLOWS_FAULT_AT");
  if (at == nullptr || std::atol(at) != n) return false;
  const char* mode = std::getenv("BELLOWS_FAULT_MODE");
  if (mode == nullptr || std::strcmp(mode, "kill") == 0) {
    ::kill(::getpid(), SIGKILL);
    ::pause();
  }
  errno = std::strcmp(mode, "eio") == 0 ? EIO : ENOSPC;
  return true;
}

bool counted_fd(int fd) {
  if (fd <= 2) return false;
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !(S_ISREG(info.st_mode) || S_ISDIR(info.st_mode))) return false;
  char link[64], target[32];
  std::snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t length = ::readlink(link, target, sizeof target);
  const bool in_memory = length >= 7 && std::memcmp(target, "/memfd:", 7) == 0;
  return !in_memory;
}

struct ShimOnlyThisProcess {
  ShimOnlyThisProcess() { ::unsetenv("LD_PRELOAD"); }
} g_shim_only_this_process;

struct CountAtExit {
  ~CountAtExit() {
    if (const char* path = std::getenv("BELLOWS_FAULT_COUNT")) {
      if (FILE* f = std::fopen(path, "w")) {
        std::fprintf(f, "%ld\n", g_counted.load());
        std::fclose(f);
      }
    }
  }
} g_count_at_exit;

}  // namespace

extern "C" {

ssize_t write(int fd, const void* data, size_t size) {
  static const auto next = real<ssize_t (*)(int, const void*, size_t)>("write");
  if (counted_fd(fd) && strike()) return -1;
  return next(fd, data, size);
}

ssize_t pwrite(int fd, const void* data, size_t size, off_t at) {  // HDF5's writes (MAT v7.3)
  static const auto next = real<ssize_t (*)(int, const void*, size_t, off_t)>("pwrite");
  if (counted_fd(fd) && strike()) return -1;
  return next(fd, data, size, at);
}

ssize_t pwrite64(int fd, const void* data, size_t size, off_t at) {
  static const auto next = real<ssize_t (*)(int, const void*, size_t, off_t)>("pwrite64");
  if (counted_fd(fd) && strike()) return -1;
  return next(fd, data, size, at);
}

// A library writing through stdio (libmatio's MAT v7.3 header): glibc's own write(2) under it is
// not interposable, so each fwrite to a counted file is a call of its own.
size_t fwrite(const void* data, size_t size, size_t count, FILE* stream) {
  static const auto next = real<size_t (*)(const void*, size_t, size_t, FILE*)>("fwrite");
  const int fd = ::fileno(stream);
  if (fd >= 0 && counted_fd(fd) && strike()) return 0;  // nothing written, errno set
  return next(data, size, count, stream);
}

int fsync(int fd) {
  static const auto next = real<int (*)(int)>("fsync");
  if (counted_fd(fd) && strike()) return -1;
  return next(fd);
}

int fdatasync(int fd) {
  static const auto next = real<int (*)(int)>("fdatasync");
  if (counted_fd(fd) && strike()) return -1;
  return next(fd);
}

int rename(const char* from, const char* to) {
  static const auto next = real<int (*)(const char*, const char*)>("rename");
  if (strike()) return -1;
  return next(from, to);
}

int renameat(int from_dir, const char* from, int to_dir, const char* to) {
  static const auto next = real<int (*)(int, const char*, int, const char*)>("renameat");
  if (strike()) return -1;
  return next(from_dir, from, to_dir, to);
}

int renameat2(int from_dir, const char* from, int to_dir, const char* to, unsigned flags) {
  static const auto next = real<int (*)(int, const char*, int, const char*, unsigned)>("renameat2");
  if (strike()) return -1;
  return next(from_dir, from, to_dir, to, flags);
}

}  // extern "C"
