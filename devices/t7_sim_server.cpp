#include "devices/t7_sim_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include <modbus/modbus.h>

#include "devices/t7_registers.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {

// The longest the server waits for a request before it advances the arm and runs the watchdog.
constexpr double kMaxWait_s = 0.001;
// The status file is rewritten at most this often (and at every watchdog action).
constexpr double kStatusPeriod_s = 0.01;
// How far the arm may fall behind before it is advanced (its step is much finer than this).
constexpr double kArmStep_s = 0.0005;

bool inlets_closed_outlets_open(const std::array<double, kValveRoleCount>& duty) {
  return duty[0] == 0.0 && duty[1] == 0.0 && duty[2] == 1.0 && duty[3] == 1.0;
}

}  // namespace

T7SimServer::T7SimServer(T7SimOptions options)
    : options_(std::move(options)), arm_(options_.plant, options_.seed), query_(MODBUS_TCP_MAX_ADU_LENGTH) {
  validate_rig_profile(options_.profile);
  if (options_.no_supply) arm_.set_supply_bar(options_.plant.gas.ambient_bar);
  arm_.vent();
  context_ = modbus_new_tcp_pi(options_.host.c_str(), std::to_string(options_.port).c_str());
  if (context_ == nullptr) throw InputError("t7-sim: bad address " + options_.host + ":" + std::to_string(options_.port));
  listen_fd_ = modbus_tcp_pi_listen(context_, 4);
  if (listen_fd_ == -1) {
    const std::string why = modbus_strerror(errno);
    modbus_free(context_);
    throw EnvironmentError("t7-sim: cannot listen on " + options_.host + ":" + std::to_string(options_.port) + " (" + why + ")");
  }
  sockaddr_storage bound{};
  socklen_t length = sizeof bound;
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&bound), &length);
  port_ = bound.ss_family == AF_INET6 ? ntohs(reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port)
                                      : ntohs(reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
  start_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  status_.safe_since_s = 0.0;
  apply_lines(0.0);
  update_inputs();
  published_ = status_;
}

T7SimServer::~T7SimServer() {
  for (int fd : clients_) close(fd);
  if (listen_fd_ != -1) close(listen_fd_);
  modbus_free(context_);
}

double T7SimServer::now_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count() - start_s_;
}

void T7SimServer::advance_arm(double now) {
  if (now - arm_time_s_ < kArmStep_s) return;
  arm_.advance(now - arm_time_s_);
  arm_time_s_ = now;
  apply_limits(false);
}

// The rig's own limits on what reaches the valves (the lines keep what the client wrote): checked
// after every step of the arm and every write, as io-sim does (RigServer::apply_limits).
void T7SimServer::apply_limits(bool write) {
  const SensorReading r = arm_.read_sensors();
  const LimitedValves limited = enforce_rig_limits(commanded_, r, options_.limits);
  const std::int32_t before = limit_bits_;
  limit_bits_ = limited.fault_bits;
  status_.chamber_bar = r.joint[0].chamber_bar;
  status_.angle_rad = r.joint[0].angle_rad;
  const auto rising = [&](std::int32_t bit) { return (limit_bits_ & bit) != 0 && (before & bit) == 0; };
  if (rising(kRigPressureLimitBit)) ++status_.pressure_limit_trips;
  if (rising(kRigAngleLimitBit)) ++status_.angle_limit_trips;
  if (events_ != nullptr && rising(kRigPressureLimitBit)) {
    (*events_)("t7-sim: a chamber at the rig's ceiling of " + std::to_string(options_.limits.pressure_ceiling_bar) + " bar: vented");
  }
  if (events_ != nullptr && rising(kRigAngleLimitBit)) (*events_)("t7-sim: the arm beyond the rig's angle range: every valve vented");
  if (limited.angle_exceeded) commanded_ = ValveCommand::vented();  // until the client writes its duties again
  // Written only when something changed: every write starts a new PWM period.
  if (write || limit_bits_ != 0 || before != 0) arm_.write_valves(limited.valves);
}

void T7SimServer::update_inputs() {
  const SensorReading r = arm_.read_sensors();
  const RigProfile& p = options_.profile;
  const std::array<double, kActuatorCount>& chambers = r.joint[0].chamber_bar;  // the simulated arm's one joint
  const double chamber_a = options_.swapped_chambers ? chambers[1] : chambers[0];
  const double chamber_b = options_.swapped_chambers ? chambers[0] : chambers[1];
  registers_.set_ain(p.input(SensorRole::kChamberA).ain, p.input(SensorRole::kChamberA).volts(chamber_a));
  registers_.set_ain(p.input(SensorRole::kChamberB).ain, p.input(SensorRole::kChamberB).volts(chamber_b));
  registers_.set_ain(p.input(SensorRole::kSupply).ain, p.input(SensorRole::kSupply).volts(r.supply_bar));
  registers_.set_ain(p.input(SensorRole::kAngle).ain, p.input(SensorRole::kAngle).volts(r.joint[0].angle_rad + p.angle_zero_rad));
  registers_.set_ain(p.input(SensorRole::kTemperature).ain, p.input(SensorRole::kTemperature).volts(r.temperature_K));
}

void T7SimServer::apply_lines(double now) {
  std::array<double, kValveRoleCount> duty{};
  for (ValveRole role : kValveRoles) duty[static_cast<int>(role)] = registers_.line_duty(options_.profile.dio(role));
  const bool safe = inlets_closed_outlets_open(duty);
  if (safe && !status_.safe) status_.safe_since_s = now;
  if (!safe) status_.safe_since_s = -1.0;
  status_.safe = safe;
  status_.duty = duty;
  ValveCommand command;  // what reaches the valves: a dead one stays shut
  for (ValveRole role : kValveRoles) {
    if (options_.dead_valve && *options_.dead_valve == role) duty[static_cast<int>(role)] = 0.0;
  }
  command.joint[0].inlet_duty = {duty[0], duty[1]};
  command.joint[0].outlet_duty = {duty[2], duty[3]};
  commanded_ = command;
  apply_limits(true);  // a new PWM period starts, as at the in-process arm's ticks
}

void T7SimServer::serve_client(int fd, double now, const std::function<void(const std::string&)>& events) {
  modbus_set_socket(context_, fd);
  const int length = modbus_receive(context_, query_.data());
  if (length == 0) return;  // not a request for this unit
  if (length < 0) {
    close(fd);
    clients_.erase(std::find(clients_.begin(), clients_.end(), fd));
    events("t7-sim: a client left (" + std::to_string(clients_.size()) + " connected)");
    return;
  }
  if (first_request_s_ < 0.0) first_request_s_ = now;
  if (options_.silent_after_s >= 0.0 && now - first_request_s_ >= options_.silent_after_s) {
    if (!status_.silent) events("t7-sim: the link is silent from now on (drill)");
    status_.silent = true;  // the request is lost on the way: no answer, and the watchdog is not fed
    return;
  }
  if (options_.stall_after_s >= 0.0 && status_.stalls == 0 && now - first_request_s_ >= options_.stall_after_s) {
    ++status_.stalls;
    char line[120];
    std::snprintf(line, sizeof line, "t7-sim: this answer comes %.3f s late (drill)", options_.stall_s);
    events(line);
    std::this_thread::sleep_for(std::chrono::duration<double>(options_.stall_s));  // the requests meanwhile queue up
  }
  const int header = modbus_get_header_length(context_);
  const int function = query_[static_cast<std::size_t>(header)];
  const int address = (query_[static_cast<std::size_t>(header + 1)] << 8) | query_[static_cast<std::size_t>(header + 2)];
  int count = (query_[static_cast<std::size_t>(header + 3)] << 8) | query_[static_cast<std::size_t>(header + 4)];
  if (function == MODBUS_FC_WRITE_SINGLE_REGISTER) count = 1;
  const int exception = registers_.check(function, address, count);
  if (exception != 0) {
    modbus_reply_exception(context_, query_.data(), static_cast<unsigned int>(exception));
    ++status_.exceptions;
  } else {
    const bool reads_inputs = (function == MODBUS_FC_READ_HOLDING_REGISTERS || function == MODBUS_FC_READ_INPUT_REGISTERS) &&
                              address < t7::kAin(t7::kAinCount);
    if (reads_inputs) {
      advance_arm(now);
      update_inputs();
    }
    modbus_mapping_t mapping{};
    mapping.nb_registers = mapping.nb_input_registers = T7SimRegisters::kSize;
    mapping.tab_registers = mapping.tab_input_registers = registers_.data();
    modbus_reply(context_, query_.data(), length, &mapping);
    const bool writes = function == MODBUS_FC_WRITE_SINGLE_REGISTER || function == MODBUS_FC_WRITE_MULTIPLE_REGISTERS;
    if (writes) {
      advance_arm(now);
      apply_lines(now);
    }
  }
  ++status_.requests;
  registers_.answered(now);
  status_.last_request_s = now;
}

void T7SimServer::run(const std::function<bool()>& should_stop, const std::function<void(const std::string&)>& events) {
  events_ = &events;
  while (!should_stop()) {
    fd_set readable;
    FD_ZERO(&readable);
    FD_SET(listen_fd_, &readable);
    int highest = listen_fd_;
    for (int fd : clients_) {
      FD_SET(fd, &readable);
      highest = std::max(highest, fd);
    }
    timeval wait{0, static_cast<suseconds_t>(kMaxWait_s * 1e6)};
    const int ready = select(highest + 1, &readable, nullptr, nullptr, &wait);
    const double now = now_s();
    if (ready > 0) {
      if (FD_ISSET(listen_fd_, &readable)) {
        const int fd = accept(listen_fd_, nullptr, nullptr);
        if (fd >= 0) {
          clients_.push_back(fd);
          events("t7-sim: a client connected (" + std::to_string(clients_.size()) + " connected)");
        }
      }
      const std::vector<int> polled = clients_;
      for (int fd : polled) {
        if (FD_ISSET(fd, &readable)) serve_client(fd, now, events);
      }
    }
    advance_arm(now);
    if (registers_.run_watchdog(now)) {
      ++status_.watchdog_actions;
      status_.last_watchdog_action_s = now;
      apply_lines(now);
      char line[200];
      std::snprintf(line, sizeof line,
                    "t7-sim: watchdog: %u s without a request at %.3f s: lines inlet_a %.3f inlet_b %.3f outlet_a %.3f outlet_b %.3f (%s)",
                    registers_.watchdog_timeout_s(), now, status_.duty[0], status_.duty[1], status_.duty[2], status_.duty[3],
                    status_.safe ? "safe" : "NOT SAFE");
      events(line);
      write_status(now, true);
    }
    write_status(now, false);
  }
  write_status(now_s(), true);
  events_ = nullptr;
}

void T7SimServer::write_status(double now, bool force) {
  status_.time_s = now;
  status_.watchdog_enabled = registers_.watchdog_enabled();
  status_.watchdog_timeout_s = registers_.watchdog_timeout_s();
  status_.clients = static_cast<int>(clients_.size());
  if (!force && now - last_status_write_s_ < kStatusPeriod_s) return;
  last_status_write_s_ = now;
  {
    const std::lock_guard<std::mutex> lock(published_mutex_);
    published_ = status_;
  }
  if (options_.status_path.empty()) return;
  const T7SimStatus& s = status_;
  char text[1100];
  std::snprintf(text, sizeof text,
                "{\"time_s\": %.6f, \"valves\": {\"inlet_a\": %.6f, \"inlet_b\": %.6f, \"outlet_a\": %.6f, \"outlet_b\": %.6f}, "
                "\"safe\": %s, \"safe_since_s\": %.6f, \"last_request_s\": %.6f, \"watchdog\": {\"enabled\": %s, "
                "\"timeout_s\": %u, \"actions\": %d, \"last_action_s\": %.6f}, \"requests\": %llu, \"exceptions\": %llu, "
                "\"clients\": %d, \"silent\": %s, \"stalls\": %d, \"pwm_period_s\": %.6f, \"chamber_bar\": [%.6f, %.6f], \"angle_rad\": %.6f, "
                "\"limits\": {\"pressure_ceiling_bar\": %.6f, \"angle_limit_rad\": %.6f, \"pressure_trips\": %d, \"angle_trips\": %d}}\n",
                s.time_s, s.duty[0], s.duty[1], s.duty[2], s.duty[3], s.safe ? "true" : "false", s.safe_since_s, s.last_request_s,
                s.watchdog_enabled ? "true" : "false", s.watchdog_timeout_s, s.watchdog_actions, s.last_watchdog_action_s,
                static_cast<unsigned long long>(s.requests), static_cast<unsigned long long>(s.exceptions), s.clients,
                s.silent ? "true" : "false", s.stalls, 1.0 / options_.profile.pwm_frequency_hz, s.chamber_bar[0], s.chamber_bar[1],
                s.angle_rad, options_.limits.pressure_ceiling_bar, options_.limits.angle_limit_rad, s.pressure_limit_trips,
                s.angle_limit_trips);
  const std::string temporary = options_.status_path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::trunc);
    out << text;
  }
  std::error_code ignored;
  std::filesystem::rename(temporary, options_.status_path, ignored);  // readers never see half a file
}

T7SimStatus T7SimServer::status() const {
  const std::lock_guard<std::mutex> lock(published_mutex_);
  return published_;
}

}  // namespace bellows
