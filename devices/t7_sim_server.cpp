#include "devices/t7_sim_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include <modbus/modbus.h>

#include "devices/latest_file_writer.hpp"
#include "devices/request_arrival.hpp"
#include "devices/t7_errors.hpp"
#include "devices/t7_registers.hpp"
#include "devices/t7_sim_rules.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {

// The longest the server waits for a request before it advances the arm and runs the watchdog.
constexpr double kMaxWait_s = 0.001;
// The status file is rewritten at most this often (and at every watchdog action).
constexpr double kStatusPeriod_s = 0.01;
// How far the arm may fall behind before it is advanced (its step is much finer than this).
constexpr double kArmStep_s = 0.0005;
// Simultaneous Modbus TCP connections a T7 serves (T-Series datasheet 6.0 "Ethernet").
constexpr int kMaxConnections = 2;
// The last stretch before an answer is due is spent polling the clock rather than asleep: a sleep
// ends a wake-up of this host late (median ~0.1 ms on the 2-core VM, far more from an idle vCPU).
constexpr double kAnswerSpin_s = 0.0002;
// An answer sent later than this beyond its due time is counted as late (T7SimStatus).
constexpr double kLateAnswer_s = 0.0005;

bool inlets_closed_outlets_open(const std::array<double, kValveRoleCount>& duty) {
  return duty[0] == 0.0 && duty[1] == 0.0 && duty[2] == 1.0 && duty[3] == 1.0;
}

}  // namespace

T7SimServer::T7SimServer(T7SimOptions options)
    : options_(std::move(options)),
      registers_(options_.product == t7::Product::kT7Pro),
      arm_(options_.plant, options_.seed),
      query_(MODBUS_TCP_MAX_ADU_LENGTH) {
  validate_rig_profile(options_.profile);
  if (options_.no_supply) arm_.set_supply_bar(options_.plant.gas.ambient_bar);
  if (options_.streaming) registers_.set_u32(t7::kStreamEnable, 1);
  arm_.vent();
  context_ = modbus_new_tcp_pi(options_.host.c_str(), std::to_string(options_.port).c_str());
  if (context_ == nullptr)
    throw InputError("t7-sim: bad address " + options_.host + ":" + std::to_string(options_.port));
  listen_fd_ = modbus_tcp_pi_listen(context_, 4);
  if (listen_fd_ == -1) {
    const std::string why = modbus_strerror(errno);
    modbus_free(context_);
    throw EnvironmentError("t7-sim: cannot listen on " + options_.host + ":" + std::to_string(options_.port) + " (" +
                           why + ")");
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
  if (!options_.status_path.empty()) status_file_ = std::make_unique<LatestFileWriter>(options_.status_path);
}

T7SimServer::~T7SimServer() {
  for (int fd : clients_) close(fd);
  if (listen_fd_ != -1) close(listen_fd_);
  modbus_free(context_);
}

double T7SimServer::now_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count() - start_s_;
}

// In steps of kArmStep_s with the rig's limits after each, however late the server comes to it (an
// answer paced at a T7's speed, a loaded machine): a pressure switch acts continuously.
void T7SimServer::advance_arm(double now) {
  while (now - arm_time_s_ >= kArmStep_s) {
    const double step =
        std::min(now - arm_time_s_, 2.0 * kArmStep_s) >= 2.0 * kArmStep_s ? kArmStep_s : now - arm_time_s_;
    arm_.advance(step);
    arm_time_s_ += step;
    apply_limits(false);
  }
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
    (*events_)("t7-sim: a chamber at the rig's ceiling of " + std::to_string(options_.limits.pressure_ceiling_bar) +
               " bar: vented");
  }
  if (events_ != nullptr && rising(kRigAngleLimitBit))
    (*events_)("t7-sim: the arm beyond the rig's angle range: every valve vented");
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
  registers_.set_ain(p.input(SensorRole::kAngle).ain,
                     p.input(SensorRole::kAngle).volts(r.joint[0].angle_rad + p.angle_zero_rad));
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

double T7SimServer::answer_time_s(int function, int address, int count) const {
  double t = t7::kEthernetOverhead_s;
  if (function != MODBUS_FC_READ_HOLDING_REGISTERS && function != MODBUS_FC_READ_INPUT_REGISTERS) return t;
  for (int ain = 0; ain < t7::kAinCount; ++ain) {
    if (address < t7::kAin(ain) + 2 && t7::kAin(ain) < address + count) {
      std::uint16_t settling[2] = {registers_.u16(t7::kAinSettling_us(ain)),
                                   registers_.u16(t7::kAinSettling_us(ain) + 1)};
      t += t7::sample_time_s(registers_.u16(t7::kAinResolutionIndex(ain)), t7::get_float(settling), options_.product);
    }
  }
  return t;
}

// The trickle drill: the answer leaves one byte at a time (the link holds, barely). Functions 3
// and 16, the ones bellows uses; the server does nothing else meanwhile, as a stuck T7 would not.
void T7SimServer::trickle_reply(int fd, int function, int address, int count) {
  std::uint8_t reply[MODBUS_TCP_MAX_ADU_LENGTH];
  std::size_t size = 0;
  for (int i = 0; i < 2; ++i) reply[size++] = query_[static_cast<std::size_t>(i)];  // transaction id
  reply[size++] = 0;
  reply[size++] = 0;
  const std::size_t length_at = size;
  size += 2;
  reply[size++] = query_[6];  // unit
  reply[size++] = static_cast<std::uint8_t>(function);
  if (function == MODBUS_FC_WRITE_MULTIPLE_REGISTERS) {
    for (int v : {address >> 8, address & 0xff, count >> 8, count & 0xff}) reply[size++] = static_cast<std::uint8_t>(v);
  } else {
    reply[size++] = static_cast<std::uint8_t>(2 * count);
    for (int i = 0; i < count; ++i) {
      const std::uint16_t r = registers_.u16(address + i);
      reply[size++] = static_cast<std::uint8_t>(r >> 8);
      reply[size++] = static_cast<std::uint8_t>(r & 0xff);
    }
  }
  reply[length_at] = static_cast<std::uint8_t>((size - 6) >> 8);
  reply[length_at + 1] = static_cast<std::uint8_t>((size - 6) & 0xff);
  for (std::size_t i = 0; i < size; ++i) {
    if (::send(fd, reply + i, 1, MSG_NOSIGNAL) != 1) return;
    std::this_thread::sleep_for(std::chrono::duration<double>(options_.trickle_byte_s));
  }
}

void T7SimServer::serve_client(int fd, double now, const std::function<void(const std::string&)>& events) {
  // The request's arrival (the kernel's stamp), before this thread woke for it: a T7's answer time counts from there.
  const double arrived_s = request_arrival_s(fd, now + start_s_) - start_s_;
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
  const bool stalled =
      options_.stall_after_s >= 0.0 && status_.stalls == 0 && now - first_request_s_ >= options_.stall_after_s;
  if (stalled) {
    ++status_.stalls;
    char line[120];
    std::snprintf(line, sizeof line, "t7-sim: this answer comes %.3f s late (drill)", options_.stall_s);
    events(line);
    std::this_thread::sleep_for(std::chrono::duration<double>(options_.stall_s));  // the requests meanwhile queue up
  }
  const int header = modbus_get_header_length(context_);
  const auto byte = [&](int i) { return static_cast<int>(query_[static_cast<std::size_t>(header + i)]); };
  const int function = byte(0);
  const int address = (byte(1) << 8) | byte(2);
  int count = (byte(3) << 8) | byte(4);
  const bool writes = function == MODBUS_FC_WRITE_SINGLE_REGISTER || function == MODBUS_FC_WRITE_MULTIPLE_REGISTERS;
  std::uint16_t values[MODBUS_MAX_WRITE_REGISTERS];
  if (function == MODBUS_FC_WRITE_SINGLE_REGISTER) {
    count = 1;
    values[0] = static_cast<std::uint16_t>((byte(3) << 8) | byte(4));
  } else if (function == MODBUS_FC_WRITE_MULTIPLE_REGISTERS) {
    count = std::min(count, MODBUS_MAX_WRITE_REGISTERS);
    for (int i = 0; i < count; ++i) values[i] = static_cast<std::uint16_t>((byte(6 + 2 * i) << 8) | byte(7 + 2 * i));
  }
  if (options_.silent_reads && !writes && address < t7::kAin(t7::kAinCount)) return;  // lost on the way (drill)
  // As long as a T7 takes: the link, and each input the request reads at its resolution index.
  // Due that long after it arrived, or after the answer before it left when it queued behind that
  // one (a T7 answers one request at a time); the stall drill may already have held it longer.
  const double due_s =
      std::max(arrived_s, busy_until_s_) + answer_time_s(function, address, count) + options_.answer_after_s;
  wait_until_s(due_s + start_s_, kAnswerSpin_s);
  now = now_s();
  busy_until_s_ = now;
  if (!stalled) {  // how much later than a T7 (this host woke late), the stall drill aside
    status_.answer_late_max_s = std::max(status_.answer_late_max_s, now - due_s);
    if (now - due_s > kLateAnswer_s) ++status_.late_answers;
  }
  const T7Refusal refusal =
      check_t7_request(registers_, options_.product, function, address, count, writes ? values : nullptr);
  if (refusal.exception != 0) {
    modbus_reply_exception(context_, query_.data(), static_cast<unsigned int>(refusal.exception));
    ++status_.exceptions;
    // As a T7 keeps it: the error and the transaction that caused it.
    registers_.data()[t7::kLastErrDetail] = static_cast<std::uint16_t>(refusal.error);
    registers_.data()[t7::kLastErrTransactionId] = static_cast<std::uint16_t>((query_[0] << 8) | query_[1]);
    if (refusal.error != t7::kErrorIllegalDataAddress && refusal.error != 1201) {
      ++status_.refusals;
      status_.last_refused_error = refusal.error;
    }
    char line[400];
    std::snprintf(line, sizeof line, "t7-sim: refused %s %s (%d): LabJack error %d %s, Modbus exception %d (%s)",
                  writes ? "writing" : "reading", t7::register_name(refusal.address).c_str(), refusal.address,
                  refusal.error, t7::error_name(refusal.error), refusal.exception, refusal.why.c_str());
    events(line);
  } else {
    const bool reads_inputs =
        (function == MODBUS_FC_READ_HOLDING_REGISTERS || function == MODBUS_FC_READ_INPUT_REGISTERS) &&
        address < t7::kAin(t7::kAinCount);
    if (reads_inputs) {
      advance_arm(now);
      update_inputs();
    }
    const bool trickles = options_.trickle_after_s >= 0.0 && now - first_request_s_ >= options_.trickle_after_s;
    if (trickles && !status_.trickling) {
      status_.trickling = true;
      events("t7-sim: answers trickle from now on, one byte every " + std::to_string(options_.trickle_byte_s) +
             " s (drill)");
    }
    if (trickles) {
      if (writes)
        for (int i = 0; i < count; ++i) registers_.data()[address + i] = values[i];
      trickle_reply(fd, function, address, count);
    } else {
      modbus_mapping_t mapping{};
      mapping.nb_registers = mapping.nb_input_registers = T7SimRegisters::kSize;
      mapping.tab_registers = mapping.tab_input_registers = registers_.data();
      modbus_reply(context_, query_.data(), length, &mapping);
    }
    if (writes) {
      registers_.wrote(address, count);
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
      // Clients first: one that left is gone before a new one is counted (never two at once).
      const std::vector<int> polled = clients_;
      for (int fd : polled) {
        if (FD_ISSET(fd, &readable)) serve_client(fd, now, events);
      }
      if (FD_ISSET(listen_fd_, &readable)) {
        const int fd = accept(listen_fd_, nullptr, nullptr);
        if (fd >= 0 && static_cast<int>(clients_.size()) >= kMaxConnections) {
          close(fd);  // a T7 serves two Modbus TCP connections at once (T-Series datasheet 6.0)
          ++status_.refused_connections;
          events("t7-sim: refused a connection: " + std::to_string(kMaxConnections) + " are open, a T7's limit");
        } else if (fd >= 0) {
          enable_arrival_stamps(fd);  // refused: the answer is timed from when this thread saw the request
          if (!options_.nagle) {
            const int one = 1;
            setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
          }
          clients_.push_back(fd);
          status_.max_clients = std::max(status_.max_clients, static_cast<int>(clients_.size()));
          events("t7-sim: a client connected (" + std::to_string(clients_.size()) + " connected)");
        }
      }
    }
    if (options_.halve_roll_after_s >= 0.0 && !roll_halved_ && first_request_s_ >= 0.0 &&
        now - first_request_s_ >= options_.halve_roll_after_s) {
      roll_halved_ = true;
      registers_.set_u32(t7::kClock0RollValue, registers_.u32(t7::kClock0RollValue) / 2);
      events("t7-sim: clock 0's roll value halved, as another program might (drill)");
    }
    advance_arm(now);
    if (registers_.run_watchdog(now)) {
      ++status_.watchdog_actions;
      if (status_.first_watchdog_action_s < 0.0 || status_.last_request_s > status_.last_watchdog_action_s) {
        status_.first_watchdog_action_s = now;
      }
      status_.last_watchdog_action_s = now;
      apply_lines(now);
      char line[200];
      std::snprintf(line, sizeof line,
                    "t7-sim: watchdog: %u s without a request at %.3f s: lines inlet_a %.3f inlet_b %.3f outlet_a %.3f "
                    "outlet_b %.3f (%s)",
                    registers_.watchdog_timeout_s(), now, status_.duty[0], status_.duty[1], status_.duty[2],
                    status_.duty[3], status_.safe ? "safe" : "NOT SAFE");
      events(line);
      write_status(now, true);
    }
    write_status(now, false);
  }
  write_status(now_s(), true);
  if (status_file_) status_file_->flush();
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
  if (!status_file_) return;
  const T7SimStatus& s = status_;
  char text[1400];
  std::snprintf(
      text, sizeof text,
      "{\"time_s\": %.6f, \"valves\": {\"inlet_a\": %.6f, \"inlet_b\": %.6f, \"outlet_a\": %.6f, \"outlet_b\": %.6f}, "
      "\"safe\": %s, \"safe_since_s\": %.6f, \"last_request_s\": %.6f, \"watchdog\": {\"enabled\": %s, "
      "\"timeout_s\": %u, \"actions\": %d, \"last_action_s\": %.6f, \"first_action_s\": %.6f}, \"requests\": %llu, "
      "\"exceptions\": %llu, "
      "\"refusals\": %llu, \"last_refused_error\": %d, "
      "\"max_clients\": %d, \"refused_connections\": %d, "
      "\"clients\": %d, \"silent\": %s, \"stalls\": %d, \"pwm_period_s\": %.6f, \"chamber_bar\": [%.6f, %.6f], "
      "\"angle_rad\": %.6f, "
      "\"limits\": {\"pressure_ceiling_bar\": %.6f, \"angle_limit_rad\": %.6f, \"pressure_trips\": %d, "
      "\"angle_trips\": %d}}\n",
      s.time_s, s.duty[0], s.duty[1], s.duty[2], s.duty[3], s.safe ? "true" : "false", s.safe_since_s, s.last_request_s,
      s.watchdog_enabled ? "true" : "false", s.watchdog_timeout_s, s.watchdog_actions, s.last_watchdog_action_s,
      s.first_watchdog_action_s, static_cast<unsigned long long>(s.requests),
      static_cast<unsigned long long>(s.exceptions), static_cast<unsigned long long>(s.refusals), s.last_refused_error,
      s.max_clients, s.refused_connections, s.clients, s.silent ? "true" : "false", s.stalls,
      1.0 / options_.profile.pwm_frequency_hz, s.chamber_bar[0], s.chamber_bar[1], s.angle_rad,
      options_.limits.pressure_ceiling_bar, options_.limits.angle_limit_rad, s.pressure_limit_trips,
      s.angle_limit_trips);
  status_file_->post(text);  // written on its own thread: a disk stall never holds an answer
}

T7SimStatus T7SimServer::status() const {
  const std::lock_guard<std::mutex> lock(published_mutex_);
  return published_;
}

}  // namespace bellows
