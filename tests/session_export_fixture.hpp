// A saved session with three iterations and one fault's black box, for the export, reader and
// figure tests.
#pragma once

#include "sessions/session_store.hpp"
#include "tests/engine_fixture.hpp"
#include "tests/session_test_support.hpp"

namespace bellows::testing {

/// The engine's own black box after a NaN angle reading while armed.
inline std::vector<TickRecord> nan_angle_black_box() {
  EngineFixture f;
  f.send(CommandKind::kArm);
  f.clock.step(500);
  f.arm.inject_fault(SimulatedFault::kNanAngle);
  for (int i = 0; i < 2000 && f.core.state() != EngineState::kFault; ++i) f.clock.step();
  return f.core.black_box().copy_frozen();
}

/// Saves a simulated session of `trials` iterations and a black box as `directory` and loads it back.
inline Session saved_faulted_session(const std::filesystem::path& directory, int trials = 3) {
  Session session = simulate_session(trials, directory.filename().string());
  session.black_boxes.push_back(nan_angle_black_box());
  session.manifest.black_boxes.push_back(
      {utc_now(), trials, "sensor-nan", static_cast<int>(session.black_boxes.back().size())});
  session.manifest.events.push_back({utc_now(), trials, "fault", "sensor-nan: angle reading is not a number"});
  save_session(session, directory);
  return load_session(directory);
}

}  // namespace bellows::testing
