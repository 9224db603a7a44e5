#include "ui/stderr_capture.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <cstdio>

namespace bellows::ui {

StderrCapture::StderrCapture() {
  std::fflush(stderr);
  int fds[2];
  // Both ends non-blocking: a writer (an I/O thread) must never stall on a full pipe; it loses the
  // line instead, which the UI drains at every frame long before 64 KiB pile up.
  if (::pipe2(fds, O_CLOEXEC | O_NONBLOCK) != 0) return;
  saved_fd_ = ::fcntl(STDERR_FILENO, F_DUPFD_CLOEXEC, 3);
  if (saved_fd_ < 0 || ::dup2(fds[1], STDERR_FILENO) < 0) {
    if (saved_fd_ >= 0) ::close(saved_fd_);
    saved_fd_ = -1;
    ::close(fds[0]);
    ::close(fds[1]);
    return;
  }
  ::close(fds[1]);  // stderr holds the write end now
  read_fd_ = fds[0];
}

StderrCapture::~StderrCapture() { restore(); }

std::vector<std::string> StderrCapture::drain() {
  std::vector<std::string> lines;
  if (read_fd_ < 0) return lines;
  std::array<char, 4096> buffer{};
  for (;;) {
    const ssize_t n = ::read(read_fd_, buffer.data(), buffer.size());
    if (n <= 0) break;  // EAGAIN: nothing more now
    partial_.append(buffer.data(), static_cast<std::size_t>(n));
  }
  std::size_t from = 0;
  for (std::size_t end = partial_.find('\n'); end != std::string::npos; end = partial_.find('\n', from)) {
    if (end > from) lines.push_back(partial_.substr(from, end - from));
    from = end + 1;
  }
  partial_.erase(0, from);
  return lines;
}

void StderrCapture::restore() {
  if (read_fd_ < 0) return;
  std::fflush(stderr);
  std::vector<std::string> rest = drain();
  if (!partial_.empty()) rest.push_back(partial_);
  ::dup2(saved_fd_, STDERR_FILENO);
  ::close(saved_fd_);
  ::close(read_fd_);
  saved_fd_ = read_fd_ = -1;
  for (const std::string& line : rest) std::fprintf(stderr, "%s\n", line.c_str());
}

}  // namespace bellows::ui
