// A Modbus TCP client for the T7: one connection, one request at a time, each answer matched to its
// request by the MBAP transaction id. Used on one thread at a time (the T7 device's constructor,
// then its I/O thread).
//
// Why not libmodbus' client (which t7-sim's server side still uses): libmodbus 3.1.6 waits per
// read() with a byte timeout (0.5 s by default), so a link that trickles a byte now and then keeps
// one request alive for seconds; and an answer that arrives after its request timed out is taken
// for the next request's, which fails "Invalid data" (and its recovery flushes whatever came).
// Here every request has one deadline for the whole answer, a late answer (an older transaction
// id) is read and discarded without a reconnect, and a wait can be interrupted (SIGINT while
// connecting). TCP_NODELAY is set: a request leaves at once.
#pragma once

#include <sys/socket.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "devices/name_lookup.hpp"

namespace bellows {

class ModbusClient {
 public:
  /// `host` a name or an address; nothing is sent yet.
  ModbusClient(const std::string& host, int port);
  ~ModbusClient();
  ModbusClient(const ModbusClient&) = delete;
  ModbusClient& operator=(const ModbusClient&) = delete;

  /// Opens the TCP connection (closing any old one first: never two at once), waiting at most
  /// `timeout_s` and no later than the deadline. Returns "" or why not.
  std::string connect(double timeout_s);
  /// Closes the connection (the next request opens a new one).
  void close();
  bool connected() const { return fd_ >= 0; }

  /// Each request waits at most this long for its whole answer...
  void set_response_timeout(double timeout_s) { response_timeout_s_ = timeout_s; }
  /// ...and never past this steady-clock time (monotonic_s(); infinity: no such limit).
  void set_deadline(double deadline_s) { deadline_s_ = deadline_s; }
  void clear_deadline() { deadline_s_ = std::numeric_limits<double>::infinity(); }
  /// While set (not null), a wait ends as soon as *stop is true: interrupted() tells.
  void set_stop(const std::atomic<bool>* stop) { stop_ = stop; }

  // Requests (function 3 reads, 16 writes). False on an error, an exception or a timeout:
  // last_error() says which. After a lost connection, the next request reconnects first.
  bool read(int address, int count, std::uint16_t* registers);
  bool write(int address, int count, const std::uint16_t* registers);
  bool read_u16(int address, std::uint16_t& value);
  bool read_u32(int address, std::uint32_t& value);
  bool read_float(int address, double& value);
  bool write_u16(int address, std::uint16_t value);
  bool write_u32(int address, std::uint32_t value);
  bool write_float(int address, double value);

  /// The last failure in words ("no answer within 4.0 ms", "Modbus exception 4 (...)", ...).
  const std::string& last_error() const { return last_error_; }
  /// The Modbus exception code of the last failed request (0: it was not an exception).
  int last_exception() const { return last_exception_; }
  /// The last failure was a timeout (the answer may still come: it will be discarded).
  bool timed_out() const { return timed_out_; }
  /// The last wait ended because *stop was set.
  bool interrupted() const { return interrupted_; }
  /// "host:port".
  const std::string& address() const { return address_; }
  /// After a read timed out and before the next request: its answer, if it has come meanwhile
  /// (never waits), into `registers` (as many as the read asked for). A reading that missed its
  /// exchange's deadline is still a reading of the inputs a moment ago, and a late answer usually
  /// comes well before the next tick: handed over, it costs no tick. Answers to other timed-out
  /// requests are dropped as a request drops them. False while nothing came, after a newer request
  /// or when the connection failed (the next request reconnects).
  bool take_late_read(std::uint16_t* registers);
  /// Answers to earlier, timed-out requests read and discarded since the start.
  std::uint64_t late_answers() const { return late_answers_; }
  /// Answers to timed-out reads that take_late_read() handed over since the start.
  std::uint64_t late_reads_taken() const { return late_reads_taken_; }
  /// When bytes last came from the T7 (monotonic_seconds(); -infinity before any): an answer in time,
  /// a late one or a part of one. A T7 that answers late is heard; a dead one is not.
  double last_receive_s() const { return last_receive_s_; }
  /// Connections opened again after one was lost.
  std::uint64_t reconnects() const { return reconnects_; }
  /// Times the host name was looked up: once, at the first connect that resolved it (within that
  /// connect's deadline: devices/name_lookup.hpp). A reconnect reuses those addresses, so it waits
  /// on nothing but the connection (the vent waits behind the exchange that reconnects).
  std::uint64_t address_resolutions() const { return address_resolutions_; }

 private:
  bool request(int function, int address, int count, const std::uint16_t* values, std::uint16_t* out);
  bool send_all(const std::uint8_t* bytes, std::size_t size, double deadline);
  /// Reads until a whole frame is in rx_; 1 a frame, 0 the deadline, -1 the connection failed.
  int receive_frame(double deadline);
  /// Waits for `events` on the socket until the deadline, in slices that watch *stop.
  int wait_for(short events, double deadline);
  bool fail(const std::string& why);
  void lose_connection(const std::string& why);

  /// Resolves host_ into addresses_ once, by the deadline (false, last_error_ set: not resolved;
  /// interrupted_ when *stop ended the wait).
  bool resolve(double deadline);

  std::string host_, port_, address_;
  std::vector<ResolvedAddress> addresses_;  // host_:port_, resolved at the first connect
  std::uint64_t address_resolutions_ = 0;
  int fd_ = -1;
  bool ever_connected_ = false;
  std::uint16_t transaction_ = 0;
  double response_timeout_s_ = 1.0;
  double deadline_s_ = std::numeric_limits<double>::infinity();
  const std::atomic<bool>* stop_ = nullptr;
  // A partly received frame survives a timeout: the rest comes with the next request's wait.
  std::array<std::uint8_t, 512> rx_{};
  std::size_t rx_size_ = 0;
  std::array<std::uint8_t, 300> tx_{};
  std::string last_error_;
  int last_exception_ = 0;
  bool timed_out_ = false;
  bool interrupted_ = false;
  std::uint64_t late_answers_ = 0;
  std::uint64_t late_reads_taken_ = 0;
  double last_receive_s_ = -std::numeric_limits<double>::infinity();
  struct LateRead {
    bool pending = false;  // the last request was a read that timed out, its answer not yet seen
    std::uint16_t tid = 0;
    int count = 0;
  };
  LateRead late_read_;
  std::uint64_t reconnects_ = 0;
};

/// The steady clock in seconds (the clock of ModbusClient's deadlines).
double monotonic_seconds();

}  // namespace bellows
