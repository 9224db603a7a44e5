#include "engine/model/pneumatic_arm_chain.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "engine/model/arm_chain_kernel.hpp"
#include "engine/base/errors.hpp"
#include "engine/base/units.hpp"

namespace bellows {
namespace {

constexpr double kBarPerPa = 1e-5;  // a product: a division here was the step's slowest instruction

/// Calls f(std::integral_constant<int, J>) for the chain's joint count.
template <typename F>
void with_joint_count(int joints, F&& f) {
  switch (joints) {
    case 1:
      f(std::integral_constant<int, 1>{});
      break;
    case 2:
      f(std::integral_constant<int, 2>{});
      break;
    case 3:
      f(std::integral_constant<int, 3>{});
      break;
    default:
      f(std::integral_constant<int, kMaxJoints>{});
      break;  // validate_chain allows 1..kMaxJoints
  }
}

/// The integrated states of J joints in one vector (the RK4 combinations are single vector operations):
/// angles, rates, creep, chamber A and chamber B pressures, J entries each.
template <int J>
using Physical = Eigen::Matrix<double, 5 * J, 1>;
enum Segment { kAngle = 0, kRate = 1, kCreep = 2, kChamberA = 3, kChamberB = 4 };

template <int J>
auto segment(Physical<J>& x, Segment s) {
  return x.template segment<J>(s * J);
}
template <int J>
auto segment(const Physical<J>& x, Segment s) {
  return x.template segment<J>(s * J);
}

}  // namespace

PneumaticArmChain::PneumaticArmChain(const PneumaticChainParameters& parameters, std::uint64_t seed)
    : parameters_((validate_pneumatic_chain(parameters), parameters)),
      mechanics_(parameters.chain),
      supply_Pa_(parameters.supply_bar * kPaPerBar),
      noise_(seed) {
  const int J = joints();
  for (int i = 0; i < J; ++i) {
    bellows_[static_cast<std::size_t>(i)] =
        BellowsPneumatics(parameters_.bellows[static_cast<std::size_t>(i)], parameters_.gas);
  }
  state_.angle_rad = JointVector::Zero(J);
  state_.velocity_rad_per_s = JointVector::Zero(J);
  state_.creep_rad = JointVector::Zero(J);
  const double ambient_Pa = parameters_.gas.ambient_bar * kPaPerBar;
  for (ChamberPressures& chambers : state_.chamber_Pa) chambers = {ambient_Pa, ambient_Pa};
  for (BellowsDuties& duties : state_.duties) duties = BellowsDuties{{0.0, 0.0}, {1.0, 1.0}};  // vented
  state_.noise = noise_.state();
}

PneumaticArmChain::State PneumaticArmChain::state() const {
  State s = state_;
  s.noise = noise_.state();
  return s;
}

void PneumaticArmChain::set_state(const State& state) {
  const Eigen::Index J = joints();
  if (state.angle_rad.size() != J || state.velocity_rad_per_s.size() != J || state.creep_rad.size() != J) {
    throw InputError("arm state: angle, velocity and creep need " + std::to_string(J) + " entries each");
  }
  state_ = state;
  noise_.set_state(state.noise);
}

double PneumaticArmChain::chamber_volume_m3(int joint, int chamber) const {
  return bellows_[static_cast<std::size_t>(joint)].chamber_volume_m3(chamber, state_.angle_rad(joint));
}

double PneumaticArmChain::air_mass_kg(int joint) const {
  const auto i = static_cast<std::size_t>(joint);
  return bellows_[i].air_mass_kg(state_.angle_rad(joint), state_.chamber_Pa[i]);
}

PneumaticArmChain::Reading PneumaticArmChain::read_sensors() {
  const int J = joints();
  Reading r;
  r.time_s = state_.time_s;
  r.angle_rad.resize(J);
  const double resolution_rad = parameters_.encoder_resolution_deg * std::numbers::pi / 180.0;
  const double sigma = parameters_.pressure_noise_bar;
  for (int i = 0; i < J; ++i) {
    const double angle = state_.angle_rad(i);
    r.angle_rad(i) = resolution_rad > 0.0 ? std::round(angle / resolution_rad) * resolution_rad : angle;
    for (int c = 0; c < 2; ++c) {
      r.chamber_bar[static_cast<std::size_t>(i)][c] =
          state_.chamber_Pa[static_cast<std::size_t>(i)][c] / kPaPerBar + sigma * noise_.standard_normal();
    }
  }
  r.supply_bar = supply_Pa_ / kPaPerBar + sigma * noise_.standard_normal();
  r.temperature_K = parameters_.gas.temperature_K;
  return r;
}

void PneumaticArmChain::write_valves(std::span<const BellowsDuties> duties) {
  if (static_cast<int>(duties.size()) != joints()) {
    throw InputError("arm valves: a command needs " + std::to_string(joints()) + " joints' duties, got " +
                     std::to_string(duties.size()));
  }
  for (std::size_t i = 0; i < duties.size(); ++i) {
    for (int c = 0; c < 2; ++c) {
      const double inlet = duties[i].inlet[c], outlet = duties[i].outlet[c];
      state_.duties[i].inlet[c] = std::isfinite(inlet) ? std::clamp(inlet, 0.0, 1.0) : 0.0;
      state_.duties[i].outlet[c] = std::isfinite(outlet) ? std::clamp(outlet, 0.0, 1.0) : 1.0;
    }
  }
  state_.pwm_phase_s = 0.0;  // a new command starts a new PWM period
}

void PneumaticArmChain::vent() {
  std::array<BellowsDuties, kMaxJoints> vented;
  vented.fill(BellowsDuties{{0.0, 0.0}, {1.0, 1.0}});
  write_valves(std::span<const BellowsDuties>(vented.data(), static_cast<std::size_t>(joints())));
}

void PneumaticArmChain::advance(double dt_s) {
  with_joint_count(joints(), [&]<int J>(std::integral_constant<int, J>) { advance_fixed<J>(dt_s); });
}

template <int J>
void PneumaticArmChain::advance_fixed(double dt_s) {
  using Vec = Eigen::Matrix<double, J, 1>;
  using Trig = arm_chain_kernel::Trig<J>;
  const arm_chain_kernel::Kernel<J> kernel(parameters_.chain, mechanics_.straight_inertia_kg_m2(),
                                           mechanics_.damping_Nms_per_rad());
  const double period = parameters_.pwm_period_s, supply_Pa = supply_Pa_;
  std::array<BellowsOpenings, J> open{};

  // The right-hand side with the valve openings `open` held; `trig` at the angles of x.
  auto derivative = [&](const Physical<J>& x, const Trig& trig) {
    Physical<J> d;
    const Vec q = segment<J>(x, kAngle), v = segment<J>(x, kRate), z = segment<J>(x, kCreep);
    const Vec pa = segment<J>(x, kChamberA), pb = segment<J>(x, kChamberB);
    segment<J>(d, kAngle) = v;
    segment<J>(d, kRate) = kernel.acceleration(trig, q, v, z, (pa - pb) * kBarPerPa);
    segment<J>(d, kCreep) = kernel.creep_rate(q, z);
#pragma GCC unroll 4
    for (int i = 0; i < J; ++i) {
      bellows_[static_cast<std::size_t>(i)].pressure_rates(q(i), v(i), pa(i), pb(i), open[static_cast<std::size_t>(i)],
                                                           supply_Pa, d(kChamberA * J + i), d(kChamberB * J + i));
    }
    return d;
  };
  // The trig of stage x_s, from the step's start x.
  auto trig_at = [](const Trig& trig, const Physical<J>& x, const Physical<J>& x_s) {
    const Vec q_s = segment<J>(x_s, kAngle);
    return trig.advanced(q_s - segment<J>(x, kAngle), q_s);
  };

  Physical<J> x;
  segment<J>(x, kAngle) = state_.angle_rad.template head<J>();
  segment<J>(x, kRate) = state_.velocity_rad_per_s.template head<J>();
  segment<J>(x, kCreep) = state_.creep_rad.template head<J>();
  for (int i = 0; i < J; ++i) {
    x(kChamberA * J + i) = state_.chamber_Pa[static_cast<std::size_t>(i)][0];
    x(kChamberB * J + i) = state_.chamber_Pa[static_cast<std::size_t>(i)][1];
  }
  Trig trig;
  constexpr double kEpsilon_s = 1e-12;  // no sliver steps from float drift at period boundaries
  double remaining = dt_s;
  for (int step = 0; remaining > kEpsilon_s; ++step) {
    if (step % arm_chain_kernel::kTrigRefreshSteps == 0) trig = Trig::exact(segment<J>(x, kAngle));
    if (state_.pwm_phase_s >= period - kEpsilon_s) state_.pwm_phase_s = 0.0;  // PWM repeats
    double h = std::min(parameters_.chain.integration_step_s, remaining);
#pragma GCC unroll 4
    for (int i = 0; i < J; ++i) {
      const BellowsDuties& duties = state_.duties[static_cast<std::size_t>(i)];
      h = std::min(h, pwm_time_to_next_edge(duties, state_.pwm_phase_s, period));
      open[static_cast<std::size_t>(i)] = pwm_openings(duties, state_.pwm_phase_s, period);
    }
    // Classical RK4 with the openings constant over the step (steps end on switching edges).
    const Physical<J> k1 = derivative(x, trig);
    const Physical<J> x2 = x + h / 2 * k1;
    const Physical<J> k2 = derivative(x2, trig_at(trig, x, x2));
    const Physical<J> x3 = x + h / 2 * k2;
    const Physical<J> k3 = derivative(x3, trig_at(trig, x, x3));
    const Physical<J> x4 = x + h * k3;
    const Physical<J> k4 = derivative(x4, trig_at(trig, x, x4));
    Physical<J> next = x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    segment<J>(next, kChamberA) = segment<J>(next, kChamberA).cwiseMax(1.0);  // as for one joint: never a vacuum
    segment<J>(next, kChamberB) = segment<J>(next, kChamberB).cwiseMax(1.0);
    trig = trig_at(trig, x, next);
    x = next;
    state_.pwm_phase_s += h;
    state_.time_s += h;
    remaining -= h;
  }
  state_.angle_rad = segment<J>(x, kAngle);
  state_.velocity_rad_per_s = segment<J>(x, kRate);
  state_.creep_rad = segment<J>(x, kCreep);
  for (int i = 0; i < J; ++i)
    state_.chamber_Pa[static_cast<std::size_t>(i)] = {x(kChamberA * J + i), x(kChamberB * J + i)};
}

}  // namespace bellows
