#include "bridge/telemetry_publisher.hpp"
#include "engine/rt/single_writer_counter.hpp"

#include <fcntl.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "devices/lcm_channels.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {

// How often the ring is drained: 40 ticks at 200 Hz, far below what a person watching notices,
// far above what fills the ring.
constexpr double kDrainPeriod_s = 0.02;

// The fields telemetry_t and telemetry_joints_t share, listed once.
template <typename Message>
void copy_shared_fields(const TickRecord& tick, Message& t) {
  t.tick = static_cast<std::int64_t>(tick.tick);
  t.time_s = tick.time_s;
  t.state = state_code(tick.state);
  t.fault = fault_code(tick.fault);
  t.trial_id = static_cast<std::int32_t>(tick.trial_id);
  t.sample = tick.sample;
  t.reading_time_s = tick.reading.time_s;
  t.supply_bar = tick.reading.supply_bar;
  t.temperature_K = tick.reading.temperature_K;
}

std::int64_t realtime_us() {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000 + now.tv_nsec / 1000;
}

}  // namespace

std::int8_t state_code(EngineState state) {
  switch (state) {
    case EngineState::kSafe:
      return telemetry_t::STATE_SAFE;
    case EngineState::kArmed:
      return telemetry_t::STATE_ARMED;
    case EngineState::kRunning:
      return telemetry_t::STATE_RUNNING;
    case EngineState::kFault:
      return telemetry_t::STATE_FAULT;
  }
  return -1;
}

// FaultCode's own numbering, which docs/lcm-protocol.md lists.
std::int8_t fault_code(FaultCode fault) { return static_cast<std::int8_t>(fault); }

TelemetryPublisher::TelemetryPublisher(TelemetryRing& ring, std::int64_t session_id, std::FILE* log)
    : ring_(ring), session_id_(session_id) {
  log_.f = log;
  log_.eventcount = 0;
  log_epoch_us_ = realtime_us();
  telemetry_.session_id = session_id_;
  joints_telemetry_.session_id = session_id_;
  event_.session_id = session_id_;
  buffer_.resize(4096);
}

TelemetryPublisher::~TelemetryPublisher() = default;

void TelemetryPublisher::post_trial(const IterationSummary& summary, const Eigen::VectorXd& correction_bar,
                                    double sample_s) {
  trial_summary_t message;
  message.samples = static_cast<std::int32_t>(correction_bar.size());
  message.session_id = session_id_;
  message.iteration = summary.iteration;
  message.rms_deg = summary.rms_deg;
  message.max_abs_error_deg = summary.max_abs_error_deg;
  message.max_abs_correction_bar = summary.max_abs_correction_bar;
  message.saturated_samples = summary.saturated_samples;
  message.sample_s = sample_s;
  message.correction_bar.assign(correction_bar.data(), correction_bar.data() + correction_bar.size());
  const std::lock_guard<std::mutex> lock(trials_mutex_);
  trials_.push_back(std::move(message));
}

template <typename Message>
void TelemetryPublisher::emit(lcm::LCM* bus, const char* channel, const Message& message,
                              std::atomic<std::uint64_t>& counter) {
  const std::size_t size = encode_into(message, buffer_);
  bool ok = true;
  if (bus != nullptr) ok = bus->publish(channel, buffer_.data(), static_cast<unsigned int>(size)) == 0;
  if (log_.f != nullptr) {
    lcm_eventlog_event_t event{};
    event.eventnum = 0;  // the writer numbers the events itself
    event.timestamp = log_epoch_us_ + std::llround(latest_time_s_ * 1e6);
    event.channellen = static_cast<std::int32_t>(std::strlen(channel));
    event.channel = const_cast<char*>(channel);
    event.datalen = static_cast<std::int32_t>(size);
    event.data = buffer_.data();
    if (lcm_eventlog_write_event(&log_, &event) == 0) bump(log_events_);
    else ok = false;
  }
  if (ok) bump(counter);
  else bump(errors_);
}

void TelemetryPublisher::emit_event(lcm::LCM* bus, const TickRecord& tick, std::int8_t kind, const std::string& text) {
  event_.tick = static_cast<std::int64_t>(tick.tick);
  event_.time_s = tick.time_s;
  event_.kind = kind;
  event_.from_state = state_code(previous_.state);
  event_.to_state = state_code(tick.state);
  event_.fault = fault_code(tick.fault);
  event_.trial_id = static_cast<std::int32_t>(tick.trial_id);
  event_.text = text;
  emit(bus, kEventChannel, event_, events_);
}

void TelemetryPublisher::publish_joints(lcm::LCM* bus, const TickRecord& tick, int joints) {
  telemetry_joints_t& t = joints_telemetry_;
  copy_shared_fields(tick, t);
  t.fault_joint =
      static_cast<std::int8_t>(tick.fault != FaultCode::kNone && tick.fault_joint >= 0 ? tick.fault_joint + 1 : 0);
  t.joint_count = static_cast<std::int8_t>(joints);
  for (int j = 0; j < kMaxJoints; ++j) {
    const bool used = j < joints;  // rows beyond the arm's joints stay zero
    const auto ji = static_cast<std::size_t>(j);
    const JointReading& r = tick.reading.joint[ji];
    const JointValves& v = tick.valves.joint[ji];
    t.angle_rad[j] = used ? r.angle_rad : 0.0;
    t.desired_angle_rad[j] = used ? tick.joint(j).desired_rad : 0.0;
    t.u_total_bar[j] = used ? tick.joint(j).u_total_bar : 0.0;
    t.saturation[j] = static_cast<std::int8_t>(used ? tick.joint(j).setpoints.saturation_sign : 0);
    t.setpoint_bar[j][0] = used ? tick.joint(j).setpoints.a_bar : 0.0;
    t.setpoint_bar[j][1] = used ? tick.joint(j).setpoints.b_bar : 0.0;
    for (int i = 0; i < kActuatorCount; ++i) {
      t.chamber_bar[j][i] = used ? r.chamber_bar[static_cast<std::size_t>(i)] : 0.0;
      t.inlet_duty[j][i] = used ? v.inlet_duty[static_cast<std::size_t>(i)] : 0.0;
      t.outlet_duty[j][i] = used ? v.outlet_duty[static_cast<std::size_t>(i)] : 0.0;
    }
  }
  t.dropped_ticks = static_cast<std::int64_t>(dropped_ticks_.load(std::memory_order_relaxed));
  emit(bus, kTelemetryChannel, t, ticks_);
}

void TelemetryPublisher::on_tick(lcm::LCM* bus, const TickRecord& tick) {
  if (have_previous_ && tick.tick > previous_.tick + 1) bump(dropped_ticks_, tick.tick - previous_.tick - 1);
  latest_time_s_ = tick.time_s;

  // The arm's joints as the reading carries them: one speaks telemetry_t, several telemetry_joints_t.
  const int joints = std::clamp(tick.reading.joint_count, 1, kMaxJoints);
  if (joints > 1) {
    publish_joints(bus, tick, joints);
  } else {
    telemetry_t& t = telemetry_;
    copy_shared_fields(tick, t);
    t.angle_rad = tick.reading.joint[0].angle_rad;
    t.desired_angle_rad = tick.joint(0).desired_rad;
    for (int i = 0; i < kActuatorCount; ++i) {
      t.chamber_bar[i] = tick.reading.joint[0].chamber_bar[i];
      t.inlet_duty[i] = tick.valves.joint[0].inlet_duty[i];
      t.outlet_duty[i] = tick.valves.joint[0].outlet_duty[i];
    }
    t.u_total_bar = tick.joint(0).u_total_bar;
    t.setpoint_bar[0] = tick.joint(0).setpoints.a_bar;
    t.setpoint_bar[1] = tick.joint(0).setpoints.b_bar;
    t.saturation = static_cast<std::int8_t>(tick.joint(0).setpoints.saturation_sign);
    t.dropped_ticks = static_cast<std::int64_t>(dropped_ticks_.load(std::memory_order_relaxed));
    emit(bus, kTelemetryChannel, t, ticks_);
  }

  // Events, from what changed since the previous tick (before the first: the engine's initial
  // state, SAFE, no fault, no trial).
  const bool state_changed = tick.state != previous_.state;
  if (state_changed && previous_.state == EngineState::kRunning) {
    emit_event(bus, tick, engine_event_t::KIND_TRIAL_ENDED,
               "trial " + std::to_string(previous_.trial_id) + " ended in " + to_string(tick.state));
  }
  if (state_changed) {
    emit_event(bus, tick, engine_event_t::KIND_STATE_CHANGED,
               std::string(to_string(previous_.state)) + " -> " + to_string(tick.state));
  }
  if (tick.fault != FaultCode::kNone && tick.fault != previous_.fault) {
    emit_event(bus, tick, engine_event_t::KIND_FAULT,
               std::string(fault_name(tick.fault)) + ": " + fault_message(tick.fault));
  }
  if (tick.trial_id != previous_.trial_id) {
    emit_event(bus, tick, engine_event_t::KIND_TRIAL_STARTED, "trial " + std::to_string(tick.trial_id) + " started");
  }
  previous_ = tick;
  have_previous_ = true;
}

void TelemetryPublisher::drain(lcm::LCM* bus) {
  TickRecord tick;
  while (ring_.pop(tick)) on_tick(bus, tick);
  std::deque<trial_summary_t> trials;
  {
    const std::lock_guard<std::mutex> lock(trials_mutex_);
    trials.swap(trials_);
  }
  for (const trial_summary_t& trial : trials) emit(bus, kTrialChannel, trial, trials_published_);
}

double TelemetryPublisher::service(lcm::LCM* bus, double now_s) {
  drain(bus);
  return now_s + kDrainPeriod_s;
}

void TelemetryPublisher::finish(lcm::LCM* bus, double) {
  drain(bus);
  if (log_.f != nullptr) std::fflush(log_.f);  // the caller publishes it (and sees a failed flush)
}

TelemetryPublisherStats TelemetryPublisher::stats() const {
  constexpr auto relaxed = std::memory_order_relaxed;
  TelemetryPublisherStats s;
  s.ticks = ticks_.load(relaxed);
  s.dropped_ticks = dropped_ticks_.load(relaxed);
  s.events = events_.load(relaxed);
  s.trials = trials_published_.load(relaxed);
  s.log_events = log_events_.load(relaxed);
  s.errors = errors_.load(relaxed);
  return s;
}

}  // namespace bellows
