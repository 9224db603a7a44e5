// A fault's black box in a session: written by the writer, listed by the manifest, loaded back
// tick for tick (including the bad reading that caused the fault), checked when damaged.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

#include "engine/base/errors.hpp"
#include "sessions/black_box_file.hpp"
#include "sessions/file_digest.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_store.hpp"
#include "sessions/session_writer.hpp"
#include "tests/engine_fixture.hpp"
#include "tests/session_test_support.hpp"

namespace bellows {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

// The engine's own black box after `fault` was injected while armed.
std::vector<TickRecord> black_box_of(SimulatedFault fault) {
  testing::EngineFixture f;
  f.send(CommandKind::kArm);
  f.clock.step(500);
  f.arm.inject_fault(fault);
  for (int i = 0; i < 2000 && f.core.state() != EngineState::kFault; ++i) f.clock.step();
  EXPECT_EQ(f.core.state(), EngineState::kFault);
  return f.core.black_box().copy_frozen();
}

bool same_number(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

void expect_same_ticks(const std::vector<TickRecord>& loaded, const std::vector<TickRecord>& saved) {
  ASSERT_EQ(loaded.size(), saved.size());
  for (std::size_t i = 0; i < saved.size(); ++i) {
    const TickRecord& a = loaded[i];
    const TickRecord& b = saved[i];
    SCOPED_TRACE("tick " + std::to_string(i));
    EXPECT_EQ(a.tick, b.tick);
    EXPECT_EQ(a.time_s, b.time_s);
    EXPECT_EQ(a.reading.time_s, b.reading.time_s);
    EXPECT_EQ(a.state, b.state);
    EXPECT_EQ(a.fault, b.fault);
    EXPECT_TRUE(same_number(a.reading.joint[0].angle_rad, b.reading.joint[0].angle_rad))
        << a.reading.joint[0].angle_rad << " " << b.reading.joint[0].angle_rad;
    EXPECT_EQ(a.joint(0).desired_rad, b.joint(0).desired_rad);
    EXPECT_EQ(a.reading.joint[0].chamber_bar, b.reading.joint[0].chamber_bar);
    EXPECT_EQ(a.reading.supply_bar, b.reading.supply_bar);
    EXPECT_EQ(a.joint(0).u_total_bar, b.joint(0).u_total_bar);
    EXPECT_EQ(a.joint(0).setpoints.a_bar, b.joint(0).setpoints.a_bar);
    EXPECT_EQ(a.joint(0).setpoints.b_bar, b.joint(0).setpoints.b_bar);
    EXPECT_EQ(a.valves.joint[0].inlet_duty, b.valves.joint[0].inlet_duty);
    EXPECT_EQ(a.valves.joint[0].outlet_duty, b.valves.joint[0].outlet_duty);
    EXPECT_EQ(a.sample, b.sample);
    EXPECT_EQ(a.trial_id, b.trial_id);
  }
}

SessionWriter new_writer(const TempDir& dir, const std::string& name) {
  const Session simulated = testing::simulate_session(1);
  SessionManifest header = simulated.manifest;
  header.iterations.clear();
  header.resume.reset();
  return SessionWriter::create(dir.path(), name, header, simulated.trajectory, "test");
}

TEST(SessionBlackBox, TheFaultsTicksRoundTripIncludingTheNanThatCausedIt) {
  const std::vector<TickRecord> box = black_box_of(SimulatedFault::kNanAngle);
  ASSERT_FALSE(box.empty());
  ASSERT_TRUE(std::isnan(box.back().reading.joint[0].angle_rad));  // the reading the guard caught
  EXPECT_EQ(box.back().fault, FaultCode::kSensorNotANumber);
  const std::string text = format_black_box_csv(box);
  expect_same_ticks(parse_black_box_csv(text, "box.csv", static_cast<int>(box.size())), box);
}

TEST(SessionBlackBox, WriterSavesItAndLoadingGivesItBack) {
  TempDir dir;
  SessionWriter writer = new_writer(dir, "s");
  const std::vector<TickRecord> stale = black_box_of(SimulatedFault::kSensorDropout);
  const std::vector<TickRecord> supply = black_box_of(SimulatedFault::kSupplyLoss);
  writer.save_black_box("sensor-stale", stale);
  writer.save_black_box("supply-low", supply);
  EXPECT_TRUE(fs::exists(dir / "s" / session_layout::black_box_file(0)));
  EXPECT_TRUE(fs::exists(dir / "s" / session_layout::black_box_file(1)));

  const Session loaded = load_session(dir / "s");
  ASSERT_EQ(loaded.manifest.black_boxes.size(), 2u);
  EXPECT_EQ(loaded.manifest.black_boxes[0].fault, "sensor-stale");
  EXPECT_EQ(loaded.manifest.black_boxes[0].ticks, static_cast<int>(stale.size()));
  EXPECT_EQ(loaded.manifest.black_boxes[1].fault, "supply-low");
  EXPECT_EQ(loaded.manifest.black_boxes[1].iteration, 0);
  ASSERT_EQ(loaded.black_boxes.size(), 2u);
  expect_same_ticks(loaded.black_boxes[0], stale);
  expect_same_ticks(loaded.black_boxes[1], supply);

  // Saving the loaded session elsewhere keeps them.
  save_session(loaded, dir / "copy");
  const Session copy = load_session(dir / "copy");
  ASSERT_EQ(copy.black_boxes.size(), 2u);
  expect_same_ticks(copy.black_boxes[1], supply);
  EXPECT_THROW(writer.save_black_box("none", {}), std::invalid_argument);
}

TEST(SessionBlackBox, AManifestWithoutBlackBoxesStillLoads) {
  TempDir dir;
  new_writer(dir, "s");
  const fs::path manifest = dir / "s" / session_layout::kManifest;
  std::string text = testing::read_text(manifest);
  const std::size_t at = text.find(",\n  \"black_boxes\": []");
  ASSERT_NE(at, std::string::npos) << text;
  text.erase(at, std::string(",\n  \"black_boxes\": []").size());
  testing::write_text(manifest, text);
  EXPECT_TRUE(load_session(dir / "s").black_boxes.empty());
}

std::string load_error(const fs::path& directory) {
  try {
    load_session(directory);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(SessionBlackBox, DamageIsReportedWithTheFileAndLine) {
  TempDir dir;
  {
    SessionWriter writer = new_writer(dir, "s");
    writer.save_black_box("supply-low", black_box_of(SimulatedFault::kSupplyLoss));
  }
  const fs::path file = dir / "s" / session_layout::black_box_file(0);
  const std::string good = testing::read_text(file);
  const auto damaged = [&](const std::string& text) {
    testing::write_text(file, text);
    // With its digest updated, so the damage reaches the parser's checks (not the digest's).
    auto manifest = nlohmann::ordered_json::parse(testing::read_text(dir / "s" / "manifest.json"));
    manifest["black_boxes"][0]["sha256"] = sha256_hex(text);
    testing::write_text(dir / "s" / "manifest.json", manifest.dump(2));
    return load_error(dir / "s");
  };
  const std::size_t second_line = good.find('\n') + 1;
  const std::size_t third_line = good.find('\n', second_line) + 1;
  EXPECT_NE(damaged(good.substr(0, third_line)).find("expected 400 rows"), std::string::npos);
  EXPECT_NE(damaged(good.substr(0, good.size() - 3)).find("truncated"), std::string::npos);
  EXPECT_NE(damaged("tick,time\n" + good.substr(second_line)).find("line 1: the header"), std::string::npos);
  // A state that does not exist (a code where a name belongs), on line 2.
  std::string bad_state = good;
  std::size_t field = second_line;
  for (int comma = 0; comma < 3; ++comma) field = bad_state.find(',', field) + 1;
  bad_state.replace(field, bad_state.find(',', field) - field, "7");
  EXPECT_NE(damaged(bad_state).find("line 2: state '7' is not one of SAFE, ARMED, RUNNING, FAULT"), std::string::npos)
      << damaged(bad_state);
  // Ticks out of order.
  const std::string swapped =
      good.substr(0, second_line) + good.substr(third_line, good.find('\n', third_line) + 1 - third_line) +
      good.substr(second_line, third_line - second_line) + good.substr(good.find('\n', third_line) + 1);
  EXPECT_NE(damaged(swapped).find("line 3: tick"), std::string::npos) << damaged(swapped);
  fs::remove(file);
  EXPECT_NE(load_error(dir / "s").find(session_layout::black_box_file(0)), std::string::npos);
  EXPECT_EQ(damaged(good), "");
}

TEST(SessionBlackBox, ReopeningRemovesABlackBoxTheManifestDoesNotList) {
  TempDir dir;
  {
    SessionWriter writer = new_writer(dir, "s");
    writer.save_black_box("supply-low", black_box_of(SimulatedFault::kSupplyLoss));
  }
  // A crash between the file and the manifest leaves an unlisted file behind.
  fs::copy_file(dir / "s" / session_layout::black_box_file(0), dir / "s" / session_layout::black_box_file(1));
  Session loaded;
  SessionWriter writer = SessionWriter::open(dir / "s", "test", loaded);
  EXPECT_EQ(loaded.black_boxes.size(), 1u);
  EXPECT_TRUE(fs::exists(dir / "s" / session_layout::black_box_file(0)));
  EXPECT_FALSE(fs::exists(dir / "s" / session_layout::black_box_file(1)));
}

}  // namespace
}  // namespace bellows
