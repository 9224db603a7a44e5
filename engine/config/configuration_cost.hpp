// The memory and time a configuration implies, checked before anything is allocated or run.
// Each key's own range (engine/config/configuration.cpp) bounds it alone; these budgets bound what several
// keys imply together: a 10 us tick with a 60 s black box, a 1 us integration step under a 1 s tick,
// a trial of millions of ticks. The budgets are far above any lab's use (docs/configuration.md) and
// far below what takes a machine down or runs for hours, so a typo is refused, not obeyed.
#pragma once

#include <cstdint>

#include "engine/config/configuration.hpp"

namespace bellows {

namespace cost_budget {
/// Ticks a single trial (settling included) or identification trial may have: its record holds
/// 11 doubles per tick.
inline constexpr std::int64_t kMaxTicksPerTrial = 1'000'000;
/// Bytes of the black box ring (its ticks times the size of one tick's record).
inline constexpr std::int64_t kMaxBlackBoxBytes = 64ll << 20;
/// Steps of the simulated arm's integrator within one tick (tick_s / integration_step_s).
inline constexpr std::int64_t kMaxIntegrationStepsPerTick = 10'000;
/// Learning samples of a trial for the dense norm-optimal law, which holds several N x N matrices.
inline constexpr std::int64_t kMaxDenseLawSamples = 4'000;  // ~0.5 GB, as bench/bench_ilc.cpp measures
/// ADMM iterations times learning samples of one noilc-constrained update (each iteration is a
/// Riccati sweep over the trial): the longest pause between trials.
inline constexpr std::int64_t kMaxAdmmWork = 200'000'000;
}  // namespace cost_budget

/// Checks what the configuration alone implies (black box, integration steps, settling and
/// identification ticks). Throws InputError naming the keys and the budget. validate_configuration()
/// calls it, so the TOML loader and the session manifest reader both do.
void check_configuration_cost(const Configuration& config);

/// Checks a trial of `learning_samples` samples with this configuration (its ticks, the learning
/// law's matrices and update), before the law or the record is built. Throws InputError.
void check_trial_cost(const Configuration& config, std::int64_t learning_samples);

}  // namespace bellows
