// `bellows` and `bellows console` refuse what they cannot do before touching the terminal: one line
// on stderr and exit status 2, nothing on stdout.
#include <gtest/gtest.h>

#include "tests/process_runner.hpp"

namespace bellows {
namespace {

using testing::run_process;

void expect_refused(const std::string& args, const std::string& fragment) {
  // stdin from /dev/null and stdout into a pipe: no terminal.
  const auto result = run_process(std::string(BELLOWS_BINARY) + " " + args + " < /dev/null");
  EXPECT_EQ(result.exit_code, 2) << args << "\n" << result.err;
  EXPECT_TRUE(result.out.empty()) << args << ": " << result.out;
  EXPECT_NE(result.err.find(fragment), std::string::npos) << args << ": " << result.err;
}

TEST(UiCli, WithoutATerminalTheConsoleSaysSo) {
  expect_refused("", "the console needs a terminal");
  expect_refused("console --speed max", "the console needs a terminal");
}

TEST(UiCli, BadOptionsAreRefused) {
  expect_refused("console --device usb", "--device");
  expect_refused("console --device t7", "--device t7");
  expect_refused("console --device sim --t7 127.0.0.1", "--t7 and --rig-profile are for --device t7");
  expect_refused("console --speed 3", "--speed");
  expect_refused("console --rt sometimes", "--rt");
  expect_refused("console --stop-after-rises 0", "--stop-after-rises");
  expect_refused("console --trajectory no-such-trajectory", "no-such-trajectory");
  expect_refused("console --session /no/such/session", "/no/such/session");
}

TEST(UiCli, ABadConfigurationIsRefusedWithItsKey) {
  const auto dir = testing::make_temp_dir("bellows-ui-cli");
  const auto config = testing::write_file(dir, "bad.toml", "[controller]\nk_p = -1.0\n");
  expect_refused("console --config " + config.string(), "k_p");
}

}  // namespace
}  // namespace bellows
