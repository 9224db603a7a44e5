// The bus attacks of issue #16 between processes: `bellows io-sim` (and `bellows run --device lcm`)
// over UDP multicast inside a private network namespace this test makes for itself (as
// test_lcm_processes does; skipped, saying why, where none can be made), the test playing a host on
// the same bus without the key. And the key file's refusals on the command line.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>

#include <algorithm>
#include <atomic>

#include <nlohmann/json.hpp>

#include "devices/lcm_channels.hpp"
#include "devices/lcm_codec.hpp"
#include "devices/lcm_rig_limits.hpp"
#include "tests/lcm_test_support.hpp"
#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::expect_refused_in_one_line;

using testing::Child;

using testing::kBellows;

/// A host on the bus without the key, speaking the protocol. Mode kIdleRig: it takes the rig as
/// soon as it is free and drives inlet A fully open (B vented), every 2 ms. Mode kFollow: it lets
/// the engine bind, then sends commands of the engine's own session just ahead of its sequence.
class Forger final : public LcmEndpoint {
 public:
  enum class Mode { kIdleRig, kFollow };
  explicit Forger(Mode mode) : mode_(mode) {}
  void attach(lcm::LCM& bus) override { subscribe(bus, kIoStateChannel); }
  void on_message(const char*, const void* data, std::size_t size) override {
    io_state_t s{};
    if (decode_checked(data, size, s) != DecodeStatus::kOk) return;
    last_ = s;
    seen_ = true;
    max_chamber_a_bar_.store(std::max(max_chamber_a_bar_.load(), s.chamber_bar[0]));
  }
  double service(lcm::LCM* bus, double now_s) override {
    if (bus == nullptr || !seen_ || now_s < next_s_) return std::max(next_s_, now_s + 0.002);
    next_s_ = now_s + 0.002;
    io_command_t c{};
    c.rig_id = last_.rig_id;
    c.binding = last_.binding;
    if (mode_ == Mode::kIdleRig) {
      c.session_id = kSession;
      if (last_.session_id == 0) {  // bind with a vent
        c.seq = ++seq_;
        send(*bus, c);
      }
      c.seq = ++seq_;
    } else {
      if (last_.session_id == 0 || last_.session_id == kSession) return next_s_;
      c.session_id = last_.session_id;  // the engine's
      c.seq = last_.command_seq + 2;
    }
    c.armed = true;
    c.inlet_duty[0] = 1.0;
    c.outlet_duty[1] = 1.0;
    send(*bus, c);
    ++sent_;
    return next_s_;
  }
  double max_chamber_a_bar() const { return max_chamber_a_bar_.load(); }
  std::uint64_t sent() const { return sent_.load(); }

 private:
  static constexpr std::int64_t kSession = 31337;
  void send(lcm::LCM& bus, const io_command_t& c) {
    const std::size_t size = encode_signed(c, LcmKey{}, buffer_);
    bus.publish(kIoCommandChannel, buffer_.data(), static_cast<unsigned int>(size));
  }
  Mode mode_;
  io_state_t last_{};
  bool seen_ = false;
  double next_s_ = 0.0;
  std::int64_t seq_ = 0;
  std::vector<std::uint8_t> buffer_;
  std::atomic<double> max_chamber_a_bar_{0.0};
  std::atomic<std::uint64_t> sent_{0};
};

TEST(LcmProcessAttacks, ForgedCommandsOnAnIdleRigMeetItsPressureCeiling) {
  ENTER_PRIVATE_NETWORK_NAMESPACE_OR_SKIP();
  const auto dir = testing::make_temp_dir("bellows-lcm-idle-attack");
  Child rig({kBellows, "io-sim", "--json"}, dir / "rig.out", dir / "rig.err");
  ASSERT_TRUE(rig.started());
  Forger forger(Forger::Mode::kIdleRig);
  LcmIoThread bus(kDefaultLcmUrl, {&forger});
  bus.start(RealtimeMode::kOff, 0);
  ASSERT_TRUE(testing::eventually([&] { return forger.sent() > 0; }, 20.0)) << rig.err();
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the 1.5 s
  bus.stop();
  rig.signal(SIGTERM);
  ASSERT_TRUE(rig.wait(30.0).has_value());
  const double ceiling = RigLimits::from(Configuration{}).pressure_ceiling_bar;
  std::cerr << "1.5 s of forged commands: chamber A at most " << forger.max_chamber_a_bar() << " bar (ceiling "
            << ceiling << ")\n";
  EXPECT_GT(forger.max_chamber_a_bar(), 1.5) << "the forger did drive the rig";
  EXPECT_LE(forger.max_chamber_a_bar(),
            ceiling + 0.01 + 4 * Configuration{}.plant.pressure_noise_bar);  // as read, with noise
  const nlohmann::json report = nlohmann::json::parse(rig.out());
  EXPECT_GT(report["pressure_limit_trips"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(report["authenticated"], false);
  EXPECT_NE(rig.err().find("above the rig's ceiling"), std::string::npos) << rig.err();
  EXPECT_NE(rig.err().find("no key: commands NOT authenticated"), std::string::npos) << rig.err();
}

TEST(LcmProcessAttacks, WithoutAKeyATakeoverIsDiagnosedNotCalledAStaleSensor) {
  ENTER_PRIVATE_NETWORK_NAMESPACE_OR_SKIP();
  const auto dir = testing::make_temp_dir("bellows-lcm-takeover");
  Child rig({kBellows, "io-sim", "--json"}, dir / "rig.out", dir / "rig.err");
  Forger forger(Forger::Mode::kFollow);
  LcmIoThread bus(kDefaultLcmUrl, {&forger});
  bus.start(RealtimeMode::kOff, 0);
  Child run({kBellows, "run", "--no-save", "--device", "lcm", "--clock", "wall", "--iterations", "2", "--json"},
            dir / "run.out", dir / "run.err");
  ASSERT_TRUE(rig.started() && run.started());
  const auto status = run.wait(120.0);
  ASSERT_TRUE(status.has_value()) << "the engine did not stop";
  bus.stop();
  rig.signal(SIGTERM);
  ASSERT_TRUE(rig.wait(30.0).has_value());
  EXPECT_EQ(*status, 3) << run.err();
  ASSERT_GT(forger.sent(), 0u);
  const nlohmann::json report = nlohmann::json::parse(run.out());
  EXPECT_EQ(report["fault"]["name"], "foreign-sender") << report.dump();
  EXPECT_NE(report["fault"]["message"].get<std::string>().find("another sender is commanding this rig"),
            std::string::npos);
  EXPECT_NE(run.err().find("bellows: another sender is commanding this rig"), std::string::npos) << run.err();
  EXPECT_GT(report["lcm"]["rig"]["commands_not_ours"].get<std::uint64_t>(), 0u);
}

TEST(LcmKeyCli, AWorldReadableOrWrongSizedKeyIsRefusedWithOneLine) {
  const auto dir = testing::make_temp_dir("bellows-lcm-key-cli");
  const auto world = testing::write_file(dir, "world.key", std::string(32, 'w'));
  chmod(world.c_str(), 0644);
  const auto small = testing::write_file(dir, "small.key", std::string(16, 's'));
  chmod(small.c_str(), 0600);
  const auto world_config = testing::write_file(dir, "world.toml", "[lcm]\nkey_file = \"world.key\"\n");
  const auto small_config = testing::write_file(dir, "small.toml", "[lcm]\nkey_file = \"small.key\"\n");
  expect_refused_in_one_line("io-sim --config " + world_config.string(), "readable or writable by everyone");
  expect_refused_in_one_line("io-sim --config " + small_config.string(), "16 bytes; a key is exactly 32 bytes");
  expect_refused_in_one_line("run --no-save --device lcm --clock wall --lcm memq:// --config " + world_config.string(),
                             "readable or writable by everyone");
  expect_refused_in_one_line("run --no-save --device lcm --clock wall --lcm memq:// --config " + small_config.string(),
                             "exactly 32 bytes");
}

}  // namespace
}  // namespace bellows
