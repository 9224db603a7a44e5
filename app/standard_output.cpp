#include "app/standard_output.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <streambuf>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {

/// Passes everything to std::cout's own buffer (so the order with stdio is kept) and remembers the
/// reason of the first write that failed: by exit, errno is long gone.
class ErrorRecordingBuffer : public std::streambuf {
 public:
  void attach(std::streambuf* inner) { inner_ = inner; }
  std::streambuf* inner() const { return inner_; }
  int first_error() const { return first_error_; }

 protected:
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    errno = 0;
    const int_type put = inner_->sputc(traits_type::to_char_type(c));
    if (traits_type::eq_int_type(put, traits_type::eof())) record();
    return put;
  }
  std::streamsize xsputn(const char* data, std::streamsize count) override {
    errno = 0;
    const std::streamsize put = inner_->sputn(data, count);
    if (put != count) record();
    return put;
  }
  int sync() override {
    errno = 0;
    const int synced = inner_->pubsync();
    if (synced != 0) record();
    return synced;
  }

 private:
  void record() {
    if (first_error_ == 0) first_error_ = errno != 0 ? errno : EIO;
  }
  std::streambuf* inner_ = nullptr;
  int first_error_ = 0;
};

ErrorRecordingBuffer recording;

void close_standard_output() {
  std::cout.flush();
  const bool stream_failed = !std::cout.good();
  std::cout.rdbuf(recording.inner());  // `recording` may be destroyed before the streams are
  errno = 0;
  const bool flush_failed = std::fflush(stdout) != 0;
  const int error_number = recording.first_error() != 0 ? recording.first_error() : errno;
  if (!stream_failed && !flush_failed && std::ferror(stdout) == 0) return;
  std::fprintf(stderr, "bellows: cannot write to standard output: %s\n",
               error_number != 0 ? std::strerror(error_number) : "a write failed");
  std::_Exit(kExitEnvironment);  // as gnulib's close_stdout: the status must say the output is lost
}

}  // namespace

void check_standard_output_at_exit() {
  recording.attach(std::cout.rdbuf());
  std::cout.rdbuf(&recording);
  std::atexit(close_standard_output);
}

}  // namespace bellows
