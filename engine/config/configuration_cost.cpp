#include "engine/config/configuration_cost.hpp"

#include <cmath>
#include <sstream>

#include "engine/rt/engine_messages.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {

// A count from a ratio of durations, saturated instead of overflowing: the ratio of two in-range
// values may exceed any integer type, and a wrapped count would pass the budget.
std::int64_t ratio_count(double numerator, double denominator) {
  const double count = std::ceil(numerator / denominator - 1e-9);
  if (!(count < 9.0e18)) return INT64_MAX;
  return count > 0.0 ? static_cast<std::int64_t>(count) : 0;
}

[[noreturn]] void over_budget(const std::string& what, std::int64_t amount, std::int64_t budget,
                              const std::string& fix) {
  std::ostringstream message;
  message << what << " = " << amount << ", above the budget of " << budget << "; " << fix;
  throw InputError(message.str());
}

}  // namespace

void check_configuration_cost(const Configuration& config) {
  using namespace cost_budget;
  const double tick_s = config.timing.tick_s;
  const std::int64_t steps = ratio_count(tick_s, config.plant.integration_step_s);
  if (steps > kMaxIntegrationStepsPerTick) {
    over_budget("[timing] tick_s / [plant] integration_step_s (integration steps per tick)", steps,
                kMaxIntegrationStepsPerTick, "raise integration_step_s or lower tick_s");
  }
  const std::int64_t black_box_ticks = ratio_count(config.safety.black_box_s, tick_s);
  const std::int64_t black_box_bytes =
      black_box_ticks > kMaxBlackBoxBytes ? INT64_MAX : black_box_ticks * static_cast<std::int64_t>(sizeof(TickRecord));
  if (black_box_bytes > kMaxBlackBoxBytes) {
    over_budget("[safety] black_box_s / [timing] tick_s (black box bytes)", black_box_bytes, kMaxBlackBoxBytes,
                "lower black_box_s or raise tick_s");
  }
  const std::int64_t settle_ticks = ratio_count(config.timing.longest_settle_s(), tick_s);
  if (settle_ticks > kMaxTicksPerTrial) {
    over_budget("[timing] settle_s or settle_max_s / [timing] tick_s (settling ticks)", settle_ticks, kMaxTicksPerTrial,
                "lower settle_s and settle_max_s or raise tick_s");
  }
  const std::int64_t identification_ticks = ratio_count(config.identify.duration_s, tick_s);
  if (identification_ticks > kMaxTicksPerTrial - settle_ticks) {
    over_budget("[identify] duration_s / [timing] tick_s (identification ticks)", identification_ticks,
                kMaxTicksPerTrial - settle_ticks, "lower duration_s or raise tick_s");
  }
}

void check_trial_cost(const Configuration& config, std::int64_t learning_samples) {
  using namespace cost_budget;
  const std::int64_t per_sample = config.timing.ticks_per_sample;
  const std::int64_t settle_ticks = ratio_count(config.timing.longest_settle_s(), config.timing.tick_s);
  const std::int64_t ticks =
      learning_samples > kMaxTicksPerTrial ? INT64_MAX : learning_samples * per_sample + settle_ticks;
  if (ticks > kMaxTicksPerTrial) {
    over_budget("ticks per trial (" + std::to_string(learning_samples) +
                    " learning samples x [timing] ticks_per_sample, plus settling)",
                ticks, kMaxTicksPerTrial, "use a shorter trajectory or a longer [timing] tick_s");
  }
  if (config.ilc.law == "noilc-dense" && learning_samples > kMaxDenseLawSamples) {
    over_budget("[ilc] law = 'noilc-dense': learning samples", learning_samples, kMaxDenseLawSamples,
                "use law 'noilc' (the same optimum in O(N) memory) or a shorter trajectory");
  }
  const std::int64_t admm_work =
      learning_samples > kMaxTicksPerTrial ? INT64_MAX : learning_samples * config.ilc.admm_max_iterations;
  if (config.ilc.law == "noilc-constrained" && admm_work > kMaxAdmmWork) {
    over_budget("[ilc] admm_max_iterations x learning samples (" + std::to_string(learning_samples) + ")", admm_work,
                kMaxAdmmWork, "lower admm_max_iterations or use a shorter trajectory");
  }
}

}  // namespace bellows
