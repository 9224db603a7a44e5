#include "devices/modbus_client.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "devices/t7_registers.hpp"

namespace bellows {
namespace {

constexpr int kReadHolding = 3;
constexpr int kWriteMultiple = 16;
constexpr std::size_t kHeader = 7;  // MBAP: transaction, protocol, length, unit
constexpr int kUnit = 0xFF;         // Modbus TCP's "no unit" (a T7 answers any)
// How often a wait looks at the stop flag.
constexpr double kStopSlice_s = 0.02;
// An answer whose transaction id no request carried (issue 24's words: it is no exception the device sent).
constexpr const char* kNeverSent =
    "a framing or transaction-id mismatch: the response does not answer any request sent; the device sent no "
    "exception";

const char* exception_name(int code) {
  switch (code) {
    case 1:
      return "ILLEGAL FUNCTION";
    case 2:
      return "ILLEGAL DATA ADDRESS";
    case 3:
      return "ILLEGAL DATA VALUE";
    case 4:
      return "SLAVE DEVICE FAILURE";
    case 6:
      return "SLAVE DEVICE BUSY";
    default:
      return "exception";
  }
}

void put16(std::uint8_t* at, unsigned value) {
  at[0] = static_cast<std::uint8_t>(value >> 8);
  at[1] = static_cast<std::uint8_t>(value & 0xff);
}
unsigned get16(const std::uint8_t* at) { return (static_cast<unsigned>(at[0]) << 8) | at[1]; }

std::string milliseconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f ms", s * 1e3);
  return text;
}

}  // namespace

double monotonic_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

ModbusClient::ModbusClient(const std::string& host, int port)
    : host_(host), port_(std::to_string(port)), address_(host + ":" + std::to_string(port)) {}

ModbusClient::~ModbusClient() { close(); }

void ModbusClient::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  rx_size_ = 0;  // a new connection starts a new stream
}

bool ModbusClient::fail(const std::string& why) {
  last_error_ = why;
  return false;
}

void ModbusClient::lose_connection(const std::string& why) {
  close();
  last_error_ = why;
}

int ModbusClient::wait_for(short events, double deadline) {
  interrupted_ = false;
  for (;;) {
    if (stop_ != nullptr && stop_->load(std::memory_order_relaxed)) {
      interrupted_ = true;
      return 0;
    }
    const double left = deadline - monotonic_seconds();
    if (left <= 0.0) return 0;
    pollfd p{fd_, events, 0};
    const double slice = stop_ != nullptr ? std::min(left, kStopSlice_s) : left;
    const int ms = std::max(0, static_cast<int>(std::ceil(slice * 1e3)));
    const int ready = ::poll(&p, 1, ms);
    if (ready > 0) return (p.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0 && (p.revents & events) == 0 ? -1 : 1;
    if (ready < 0 && errno != EINTR) return -1;
  }
}

bool ModbusClient::resolve(double deadline) {
  if (!addresses_.empty()) return true;
  ++address_resolutions_;
  NameLookupResult found = look_up_tcp_addresses(host_, port_, deadline, stop_);
  interrupted_ = found.interrupted;
  if (found.addresses.empty()) return fail(found.error);
  addresses_ = std::move(found.addresses);
  return true;
}

std::string ModbusClient::connect(double timeout_s) {
  close();  // never two connections at once: a T7 serves only a few
  const double deadline = std::min(monotonic_seconds() + timeout_s, deadline_s_);
  if (!resolve(deadline)) return last_error_;
  last_error_ = "no address";
  for (const ResolvedAddress& a : addresses_) {
    fd_ = ::socket(a.family, a.socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a.protocol);
    if (fd_ < 0) {
      last_error_ = std::strerror(errno);
      continue;
    }
    const int one = 1;
    setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&a.address), a.length) == 0) break;
    if (errno != EINPROGRESS) {
      last_error_ = std::strerror(errno);
      close();
      continue;
    }
    const int ready = wait_for(POLLOUT, deadline);
    int error = 0;
    socklen_t length = sizeof error;
    if (ready > 0 && getsockopt(fd_, SOL_SOCKET, SO_ERROR, &error, &length) == 0 && error == 0) break;
    last_error_ = interrupted_ ? "interrupted"
                  : ready == 0 ? "no answer within " + milliseconds(timeout_s)
                               : std::strerror(error != 0 ? error : errno);
    close();
    if (interrupted_ || ready == 0) break;
  }
  if (fd_ < 0) return last_error_;
  if (ever_connected_) ++reconnects_;
  ever_connected_ = true;
  last_error_.clear();
  return "";
}

bool ModbusClient::send_all(const std::uint8_t* bytes, std::size_t size, double deadline) {
  std::size_t sent = 0;
  while (sent < size) {
    const ssize_t n = ::send(fd_, bytes + sent, size - sent, MSG_NOSIGNAL);
    if (n > 0) {
      sent += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
      const int ready = wait_for(POLLOUT, deadline);
      if (ready > 0) continue;
      timed_out_ = ready == 0 && !interrupted_;
      if (ready < 0) lose_connection("the connection failed while sending");
      else last_error_ = interrupted_ ? "interrupted" : "the request could not leave in time";
      return false;
    }
    lose_connection(std::string("sending failed: ") + std::strerror(errno));
    return false;
  }
  return true;
}

int ModbusClient::receive_frame(double deadline) {
  for (;;) {
    if (rx_size_ >= kHeader) {
      const std::size_t length = get16(&rx_[4]);
      if (get16(&rx_[2]) != 0 || length < 2 || length > 254) {
        lose_connection("the T7's answer is not Modbus TCP (the stream lost its framing)");
        return -1;
      }
      if (rx_size_ >= 6 + length) return 1;
    }
    const int ready = wait_for(POLLIN, deadline);
    if (ready == 0) return 0;
    if (ready < 0) {
      lose_connection("the connection failed");
      return -1;
    }
    const ssize_t n = ::recv(fd_, rx_.data() + rx_size_, rx_.size() - rx_size_, 0);
    if (n == 0) {
      lose_connection("the T7 closed the connection");
      return -1;
    }
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) continue;
      lose_connection(std::string("receiving failed: ") + std::strerror(errno));
      return -1;
    }
    rx_size_ += static_cast<std::size_t>(n);
    last_receive_s_ = monotonic_seconds();
  }
}

bool ModbusClient::request(int function, int address, int count, const std::uint16_t* values, std::uint16_t* out) {
  last_exception_ = 0;
  timed_out_ = false;
  interrupted_ = false;
  late_read_.pending = false;  // this request's answer will be newer than a late read's
  const double start = monotonic_seconds();
  const double deadline = std::min(start + response_timeout_s_, deadline_s_);
  if (fd_ < 0) {  // the connection was lost: a new one (the old one is closed)
    const std::string why = connect(std::max(0.0, deadline - start));
    if (!why.empty()) return fail("cannot reconnect: " + why);
  }
  const std::uint16_t tid = ++transaction_;
  std::size_t size = 0;
  put16(&tx_[0], tid);
  put16(&tx_[2], 0);
  tx_[6] = kUnit;
  tx_[7] = static_cast<std::uint8_t>(function);
  put16(&tx_[8], static_cast<unsigned>(address));
  put16(&tx_[10], static_cast<unsigned>(count));
  if (function == kWriteMultiple) {
    tx_[12] = static_cast<std::uint8_t>(2 * count);
    for (int i = 0; i < count; ++i) put16(&tx_[13 + 2 * static_cast<std::size_t>(i)], values[i]);
    size = 13 + 2 * static_cast<std::size_t>(count);
  } else {
    size = 12;
  }
  put16(&tx_[4], static_cast<unsigned>(size - 6));
  if (!send_all(tx_.data(), size, deadline)) return false;
  for (;;) {
    const int got = receive_frame(deadline);
    if (got == 0) {
      timed_out_ = !interrupted_;
      if (timed_out_ && function == kReadHolding) late_read_ = {true, tid, count};  // take_late_read()
      return fail(interrupted_ ? "interrupted"
                               : "no answer within " + milliseconds(std::max(0.0, deadline - start)) +
                                     " (the exchange's deadline)");
    }
    if (got < 0) return false;
    const std::size_t frame = 6 + get16(&rx_[4]);
    const unsigned frame_tid = get16(&rx_[0]);
    const std::uint8_t fc = rx_[7];
    const std::uint8_t* pdu = &rx_[8];
    const std::size_t pdu_size = frame - 8;
    bool ok = false;
    bool mine = frame_tid == tid;
    if (mine && fc == (function | 0x80) && pdu_size >= 1) {
      last_exception_ = pdu[0];
      char why[80];
      std::snprintf(why, sizeof why, "%s (Modbus exception %d)", exception_name(last_exception_), last_exception_);
      last_error_ = why;
    } else if (mine && fc == function && function == kReadHolding &&
               pdu_size == 1 + 2 * static_cast<std::size_t>(count) && pdu[0] == 2 * count) {
      for (int i = 0; i < count; ++i) out[i] = static_cast<std::uint16_t>(get16(pdu + 1 + 2 * i));
      ok = true;
    } else if (mine && fc == function && function == kWriteMultiple && pdu_size == 4 &&
               get16(pdu) == static_cast<unsigned>(address) && get16(pdu + 2) == static_cast<unsigned>(count)) {
      ok = true;
    } else if (mine) {
      last_error_ = "the answer does not match its request";
    }
    std::memmove(rx_.data(), rx_.data() + frame, rx_size_ - frame);  // the frame is consumed either way
    rx_size_ -= frame;
    // An older transaction id answers a request that timed out; one never sent means the stream
    // cannot be trusted (issue 24's words: it is no exception the device sent).
    const auto behind = static_cast<std::uint16_t>(tid - frame_tid);
    if (!mine && (behind == 0 || behind > 0x7fff)) {
      lose_connection(kNeverSent);
      return false;
    }
    if (!mine) {
      ++late_answers_;  // the answer to a request that timed out: read and dropped
      continue;
    }
    return ok;
  }
}

bool ModbusClient::take_late_read(std::uint16_t* registers) {
  while (late_read_.pending && fd_ >= 0) {
    if (rx_size_ >= kHeader) {
      const std::size_t length = get16(&rx_[4]);
      if (get16(&rx_[2]) != 0 || length < 2 || length > 254) {
        lose_connection("the T7's answer is not Modbus TCP (the stream lost its framing)");
        return false;
      }
      if (rx_size_ >= 6 + length) {
        const std::size_t frame = 6 + length;
        const unsigned frame_tid = get16(&rx_[0]);
        const std::uint8_t* pdu = &rx_[8];
        const int count = late_read_.count;
        const bool answers = frame_tid == late_read_.tid && rx_[7] == kReadHolding &&
                             frame - 8 == 1 + 2 * static_cast<std::size_t>(count) && pdu[0] == 2 * count;
        if (answers)
          for (int i = 0; i < count; ++i) registers[i] = static_cast<std::uint16_t>(get16(pdu + 1 + 2 * i));
        std::memmove(rx_.data(), rx_.data() + frame, rx_size_ - frame);
        rx_size_ -= frame;
        if (static_cast<std::uint16_t>(transaction_ - frame_tid) > 0x7fff) {  // never sent
          lose_connection(kNeverSent);
          return false;
        }
        if (answers) {
          late_read_.pending = false;
          ++late_reads_taken_;
          return true;
        }
        ++late_answers_;  // another timed-out request's answer (or the read's exception): dropped
        continue;
      }
    }
    const ssize_t n = ::recv(fd_, rx_.data() + rx_size_, rx_.size() - rx_size_, MSG_DONTWAIT);
    if (n > 0) {
      rx_size_ += static_cast<std::size_t>(n);
      last_receive_s_ = monotonic_seconds();
      continue;
    }
    if (n == 0) {
      lose_connection("the T7 closed the connection");
      return false;
    }
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK)
      lose_connection(std::string("receiving failed: ") + std::strerror(errno));
    return false;
  }
  return false;
}

bool ModbusClient::read(int address, int count, std::uint16_t* registers) {
  return request(kReadHolding, address, count, nullptr, registers);
}

bool ModbusClient::write(int address, int count, const std::uint16_t* registers) {
  return request(kWriteMultiple, address, count, registers, nullptr);
}

bool ModbusClient::read_u16(int address, std::uint16_t& value) { return read(address, 1, &value); }

bool ModbusClient::read_u32(int address, std::uint32_t& value) {
  std::uint16_t r[2];
  if (!read(address, 2, r)) return false;
  value = t7::get_u32(r);
  return true;
}

bool ModbusClient::read_float(int address, double& value) {
  std::uint16_t r[2];
  if (!read(address, 2, r)) return false;
  value = t7::get_float(r);
  return true;
}

bool ModbusClient::write_u16(int address, std::uint16_t value) { return write(address, 1, &value); }

bool ModbusClient::write_u32(int address, std::uint32_t value) {
  std::uint16_t r[2];
  t7::put_u32(value, r);
  return write(address, 2, r);
}

bool ModbusClient::write_float(int address, double value) {
  std::uint16_t r[2];
  t7::put_float(value, r);
  return write(address, 2, r);
}

}  // namespace bellows
