// The identification trial: the PID (with its feed-forward) tracks a bounded excitation of the
// reference angle, a chirp or a step sequence, while the loop records angle and chamber pressures
// at the tick rate. The arm is never driven open loop, so its angle stays near the reference; the
// trial is aborted, valves vented, if it leaves [-max_abs_angle_deg, max_abs_angle_deg] anyway.
#pragma once

#include <string>

#include "engine/base/cancellation.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/base/parameters.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/trial/trial_record.hpp"

namespace bellows {

/// The other excitation: the held-out validation signal for `signal`.
std::string validation_signal(const std::string& signal);

/// "chirp": exponential sweep chirp_start_hz -> chirp_end_hz with a 1 s raised-cosine fade in and out.
/// "steps": a deterministic low-discrepancy sequence of levels in [-amplitude, amplitude], one move
/// every step_hold_s. Throws InputError for an unknown signal or inconsistent parameters.
Trajectory identification_trajectory(const std::string& signal, const IdentificationParameters& parameters,
                                     double sample_time_s);

/// An arm of `joints` joints: joint `joint` (0-based) follows `excitation` (one joint), every other
/// joint holds its start angle (0) by its PID. Named "<excitation>-joint<k>" (k 1-based).
Trajectory joint_excitation(const Trajectory& excitation, int joint, int joints);

/// Runs the excitation as a trial (of every joint of the excitation) through the engine (arming it if needed; its
/// guards apply): settles at the start, then tracks it with the PID alone. Throws InputError, after an emergency stop
/// that vents, when a joint's angle leaves +-max_abs_angle_deg; EngineFault if the engine faults; Cancelled, after an
/// emergency stop that vents, when `stop` is set (looked at every tick). The engine keeps holding
/// `excitation` after the trial, until another trajectory is selected: on a real-time loop it must
/// outlive that (the loop reads it between trials).
void run_identification_trial(EngineDriver& driver, const Trajectory& excitation, const TimingParameters& timing,
                              double max_abs_angle_deg, TrialRecord& record, StopFlag stop = nullptr);

}  // namespace bellows
