#include "devices/modbus_client.hpp"

#include <cerrno>
#include <cmath>

#include <modbus/modbus.h>

#include "devices/t7_registers.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {

void split_timeout(double timeout_s, std::uint32_t& seconds, std::uint32_t& microseconds) {
  const double t = std::fmax(timeout_s, 1e-6);
  seconds = static_cast<std::uint32_t>(t);
  microseconds = static_cast<std::uint32_t>(std::lround((t - seconds) * 1e6));
  if (microseconds >= 1000000) {
    seconds += 1;
    microseconds = 0;
  }
}

}  // namespace

ModbusClient::ModbusClient(const std::string& host, int port) : address_(host + ":" + std::to_string(port)) {
  context_ = modbus_new_tcp_pi(host.c_str(), std::to_string(port).c_str());
  if (context_ == nullptr) throw InputError("bad Modbus TCP address '" + address_ + "'");
}

ModbusClient::~ModbusClient() {
  if (context_ == nullptr) return;
  modbus_close(context_);
  modbus_free(context_);
}

std::string ModbusClient::connect(double timeout_s) {
  set_response_timeout(timeout_s);  // libmodbus waits this long for the TCP connection too
  if (modbus_connect(context_) == -1) {
    failed();
    return last_error_;
  }
  return "";
}

void ModbusClient::set_response_timeout(double timeout_s) {
  std::uint32_t s = 0, us = 0;
  split_timeout(timeout_s, s, us);
  modbus_set_response_timeout(context_, s, us);
}

bool ModbusClient::failed() {
  const int error = errno;
  last_error_ = modbus_strerror(error);
  // Only codes 1..11 are exceptions the device sent (libmodbus's EMBXILFUN..EMBXGTAR); the codes
  // after them are libmodbus's own findings about a response, which the device did not report.
  if (error >= EMBXILFUN && error <= EMBXGTAR) {
    last_error_ += " (Modbus exception " + std::to_string(error - MODBUS_ENOBASE) + ")";
  } else if (error == EMBBADDATA) {
    last_error_ += " (a framing or transaction-id mismatch: the response does not answer the request; the device sent no exception)";
  } else if (error == EMBBADSLAVE) {
    last_error_ += " (the response came from another unit id; the device sent no exception)";
  } else if (error == EMBMDATA || error == EMBBADEXC || error == EMBBADCRC) {
    last_error_ += " (a malformed response; the device sent no exception)";
  }
  return false;
}

bool ModbusClient::read(int address, int count, std::uint16_t* registers) {
  return modbus_read_registers(context_, address, count, registers) == count || failed();
}

bool ModbusClient::write(int address, int count, const std::uint16_t* registers) {
  return modbus_write_registers(context_, address, count, registers) == count || failed();
}

bool ModbusClient::read_u32(int address, std::uint32_t& value) {
  std::uint16_t r[2];
  if (!read(address, 2, r)) return false;
  value = (static_cast<std::uint32_t>(r[0]) << 16) | r[1];
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
  const std::uint16_t r[2] = {static_cast<std::uint16_t>(value >> 16), static_cast<std::uint16_t>(value & 0xffff)};
  return write(address, 2, r);
}

bool ModbusClient::write_float(int address, double value) {
  std::uint16_t r[2];
  t7::put_float(value, r);
  return write(address, 2, r);
}

bool ModbusClient::reconnect() {
  modbus_close(context_);
  return modbus_connect(context_) == 0 || failed();
}

}  // namespace bellows
