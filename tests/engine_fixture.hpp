// A simulated arm, an engine and a simulated clock, for engine tests.
#pragma once

#include <vector>

#include <gtest/gtest.h>

#include "devices/simulated_arm.hpp"
#include "engine/config/configuration.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"

namespace bellows::testing {

struct EngineFixture {
  explicit EngineFixture(const Configuration& c = Configuration{}, std::uint64_t seed = 1)
      : config(c), arm(c.plant, seed), core(arm, c.controller, c.timing, c.safety), clock(core, arm) {}

  /// Sends `kind`; a full command queue fails the test (it never fills in these tests).
  void send(CommandKind kind) { EXPECT_TRUE(core.send(EngineCommand::of(kind))) << to_string(kind); }
  std::vector<EngineEvent> drain_events() {
    std::vector<EngineEvent> events;
    EngineEvent e;
    while (core.poll_event(e)) events.push_back(e);
    return events;
  }
  TickRecord snapshot() {
    TickRecord t;
    core.read_snapshot(t);
    return t;
  }

  Configuration config;
  SimulatedArm arm;
  EngineCore core;
  SimulatedClock clock;
};

}  // namespace bellows::testing
