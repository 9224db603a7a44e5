#include "devices/t7_timing.hpp"

#include <algorithm>
#include <cstdio>

#include "engine/base/errors.hpp"

namespace bellows::t7 {

const char* to_string(Product product) { return product == Product::kT7 ? "T7" : "T7-Pro"; }

int max_resolution_index(Product product) {
  return product == Product::kT7 ? kMaxResolutionIndexT7 : kMaxResolutionIndexT7Pro;
}

int effective_resolution_index(int index, Product product) {
  if (index != 0) return index;
  return product == Product::kT7 ? kDefaultResolutionIndexT7 : kDefaultResolutionIndexT7Pro;
}

double sample_time_s(int index, double settling_us, Product product) {
  const int i = std::clamp(effective_resolution_index(index, product), 1, kMaxResolutionIndexT7Pro);
  return kSampleTime_s[static_cast<std::size_t>(i)] + std::max(0.0, settling_us) * 1e-6;
}

ExchangeTime exchange_time(const RigProfile& profile, Product product) {
  ExchangeTime t;
  int highest = 0;
  for (SensorRole role : kSensorRoles) highest = std::max(highest, profile.input(role).ain);
  double slowest_s = -1.0;
  for (int ain = 0; ain <= highest; ++ain) {
    double s = sample_time_s(1, 0.0, product);  // an input in the block no sensor uses
    for (SensorRole role : kSensorRoles) {
      const SensorCalibration& c = profile.input(role);
      if (c.ain != ain) continue;
      s = sample_time_s(c.resolution_index, c.settling_us, product);
      if (s > slowest_s) {
        slowest_s = s;
        t.slowest = role;
      }
    }
    t.sampling_s += s;
    ++t.inputs;
  }
  t.read_s = kEthernetOverhead_s + t.sampling_s;
  t.exchange_s = kEthernetOverhead_s + t.read_s;
  return t;
}

void require_exchange_fits(const RigProfile& profile, Product product, double tick_s, double response_timeout_s) {
  const ExchangeTime t = exchange_time(profile, product);
  const double limit_s = std::min(tick_s, response_timeout_s);
  if (t.exchange_s <= limit_s) return;
  const SensorCalibration& c = profile.input(t.slowest);
  char line[480];
  std::snprintf(
      line, sizeof line,
      "rig profile %s: [inputs.%s] resolution_index = %d: one read of %d inputs takes %.1f ms on a %s "
      "(%.1f ms link + %.1f ms sampling, LabJack's A-1 and A-3-2-2), the exchange with the valve write %.1f ms: "
      "more than the %.1f ms tick ([timing] tick_s) and [t7] response_timeout_s (%.1f ms) allow; "
      "use a smaller resolution_index (1..8 sample in 0.04..1.1 ms)",
      profile.source.c_str(), bellows::to_string(t.slowest), c.resolution_index, t.inputs, t.read_s * 1e3,
      to_string(product), kEthernetOverhead_s * 1e3, t.sampling_s * 1e3, t.exchange_s * 1e3, tick_s * 1e3,
      response_timeout_s * 1e3);
  throw InputError(line);
}

}  // namespace bellows::t7
