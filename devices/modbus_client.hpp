// A Modbus TCP client over libmodbus: one connection, blocking requests with a response timeout.
// Used on one thread at a time (libmodbus contexts are not thread-safe): the T7 device's
// constructor, then its I/O thread.
#pragma once

#include <cstdint>
#include <string>

typedef struct _modbus modbus_t;

namespace bellows {

class ModbusClient {
 public:
  /// `host` a name or an address; nothing is sent yet.
  ModbusClient(const std::string& host, int port);
  ~ModbusClient();
  ModbusClient(const ModbusClient&) = delete;
  ModbusClient& operator=(const ModbusClient&) = delete;

  /// Opens the TCP connection, waiting at most `timeout_s`. Returns "" or why not.
  std::string connect(double timeout_s);
  void set_response_timeout(double timeout_s);

  // Requests (function 3 reads, 16 writes). False on an error or a timeout: last_error() says which.
  bool read(int address, int count, std::uint16_t* registers);
  bool write(int address, int count, const std::uint16_t* registers);
  bool read_u32(int address, std::uint32_t& value);
  bool read_float(int address, double& value);
  bool write_u16(int address, std::uint16_t value);
  bool write_u32(int address, std::uint32_t value);
  bool write_float(int address, double value);
  /// After a failed request: closes the connection and opens a new one (waiting at most the
  /// response timeout), so no answer to an older request can be taken for the next one's. False,
  /// with last_error(), when it cannot; the next request then fails at once and may try again.
  /// (Dropping what arrived is not enough: a server whose TCP holds an answer until the client's
  /// next segment acknowledges the one before, as Nagle's algorithm does, hands each answer out
  /// one request late, for good.)
  bool reconnect();

  /// The last failure in words (a Modbus exception names its number).
  const std::string& last_error() const { return last_error_; }
  /// "host:port".
  const std::string& address() const { return address_; }

 private:
  bool failed();

  modbus_t* context_ = nullptr;
  std::string address_;
  std::string last_error_;
};

}  // namespace bellows
