// `bellows` and `bellows console` refuse what they cannot do before touching the terminal: one line
// on stderr and exit status 2, nothing on stdout.
#include <gtest/gtest.h>

#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::expect_refused_in_one_line;

using testing::run_process;

TEST(UiCli, WithoutATerminalTheConsoleSaysSo) {
  expect_refused_in_one_line("", "the console needs a terminal");
  expect_refused_in_one_line("console --speed max", "the console needs a terminal");
}

TEST(UiCli, BadOptionsAreRefused) {
  expect_refused_in_one_line("console --device usb", "--device");
  expect_refused_in_one_line("console --device t7", "--device t7");
  expect_refused_in_one_line("console --device sim --t7 127.0.0.1", "--t7 and --rig-profile are for --device t7");
  expect_refused_in_one_line("console --speed 3", "--speed");
  expect_refused_in_one_line("console --rt sometimes", "--rt");
  expect_refused_in_one_line("console --stop-after-rises 0", "--stop-after-rises");
  expect_refused_in_one_line("console --trajectory no-such-trajectory", "no-such-trajectory");
  expect_refused_in_one_line("console --session /no/such/session", "/no/such/session");
}

TEST(UiCli, ABadConfigurationIsRefusedWithItsKey) {
  const auto dir = testing::make_temp_dir("bellows-ui-cli");
  const auto config = testing::write_file(dir, "bad.toml", "[controller]\nk_p = -1.0\n");
  expect_refused_in_one_line("console --config " + config.string(), "k_p");
}

// A session recorded at other ticks cannot be continued under a --config of these: its telemetry
// would not fit the session's files (ConsoleController::adopt refuses the same from the browser).
TEST(UiCli, ASessionOfOtherTicksIsRefusedWithItsTicks) {
  const auto dir = testing::make_temp_dir("bellows-ui-cli");
  const auto slow = testing::write_file(dir, "slow.toml", "[timing]\ntick_s = 0.01\nticks_per_sample = 2\n");
  const auto other = testing::write_file(dir, "other.toml", "[controller]\nk_p = 0.3\n");
  const std::string data = (dir / "data").string();
  ASSERT_EQ(run_process(testing::kBellows + " run --config " + slow.string() + " --iterations 0 --data-dir " + data +
                        " --name s")
                .exit_code,
            0);
  expect_refused_in_one_line("console --session " + data + "/s --config " + other.string(),
                             "was recorded at [timing] tick_s = 0.01 s, ticks_per_sample = 2; --config has 0.005 s, 4");
}

}  // namespace
}  // namespace bellows
