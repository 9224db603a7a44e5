// A simulated arm, an engine and a simulated clock, for engine tests.
#pragma once

#include <vector>

#include "devices/simulated_arm.hpp"
#include "engine/configuration.hpp"
#include "engine/engine_core.hpp"
#include "engine/engine_driver.hpp"

namespace bellows::testing {

struct EngineFixture {
  explicit EngineFixture(const Configuration& c = Configuration{}, std::uint64_t seed = 1)
      : config(c), arm(c.plant, seed), core(arm, c.controller, c.timing, c.safety), clock(core, arm) {}

  void send(CommandKind kind) { core.send(EngineCommand::of(kind)); }
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
