// Rig profiles: the shipped paper rig loads, and every bad profile is one InputError naming the
// file and the key. Writing the angle zero and the identified model into a profile file. The T7's
// PWM clock arithmetic.
#include <gtest/gtest.h>

#include <string>

#include <sys/stat.h>
#include <unistd.h>

#include "app/learning_model.hpp"
#include "app/rig_profile_file.hpp"
#include "app/rig_profile_write.hpp"
#include "app/toml_key_edit.hpp"
#include "sessions/atomic_file.hpp"
#include "devices/t7_registers.hpp"
#include "engine/base/errors.hpp"

namespace bellows {
namespace {

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// The message of the InputError that parsing `text` throws ("" if none).
std::string error_of(const std::string& text) {
  try {
    parse_rig_profile(text, "bad.toml");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(RigProfile, ThePaperRigLoadsWithItsWiring) {
  const RigProfile p = paper_rig_profile();
  EXPECT_EQ(p.name, "paper-rig");
  EXPECT_DOUBLE_EQ(p.pwm_frequency_hz, 200.0);
  EXPECT_EQ(p.input(SensorRole::kChamberA).ain, 0);
  EXPECT_EQ(p.input(SensorRole::kTemperature).ain, 4);
  EXPECT_EQ(p.dio(ValveRole::kInletA), 2);
  EXPECT_EQ(p.dio(ValveRole::kOutletB), 5);
  // Buerkert 8230: 0 V is ambient; LM35: 10 mV per degree C.
  EXPECT_NEAR(p.input(SensorRole::kChamberA).value(0.0), 1.01325, 1e-12);
  EXPECT_NEAR(p.input(SensorRole::kTemperature).value(0.25), 298.15, 1e-9);
  // The P4500 reads zero mid-travel.
  EXPECT_NEAR(p.input(SensorRole::kAngle).value(2.5), 0.0, 1e-3);
  EXPECT_FALSE(p.model.has_value());
}

TEST(RigProfile, CalibrationInvertsExactly) {
  const RigProfile profile = paper_rig_profile();
  const SensorCalibration& c = profile.input(SensorRole::kAngle);
  for (double volts : {0.1, 1.7, 4.9}) EXPECT_NEAR(c.volts(c.value(volts)), volts, 1e-12);
  EXPECT_TRUE(c.valid(2.5));
  EXPECT_FALSE(c.valid(0.0));  // the end of the track: a broken wiper
}

TEST(RigProfile, AnUnknownInputNamesFileAndKey) {
  const std::string text = replaced(paper_rig_profile_text(), "[inputs.temperature]", "[inputs.humidity]");
  const std::string message = error_of(text);
  EXPECT_NE(message.find("bad.toml"), std::string::npos) << message;
  EXPECT_NE(message.find("[inputs.humidity]"), std::string::npos) << message;
  EXPECT_NE(message.find("unknown input"), std::string::npos) << message;
}

TEST(RigProfile, ALineUsedTwiceIsRefused) {
  const std::string message = error_of(replaced(paper_rig_profile_text(), "outlet_b = 5", "outlet_b = 3"));
  EXPECT_NE(message.find("[valves] outlet_b"), std::string::npos) << message;
  EXPECT_NE(message.find("already inlet_b's line"), std::string::npos) << message;
}

TEST(RigProfile, AnInputUsedTwiceIsRefused) {
  const std::string text =
      replaced(paper_rig_profile_text(), "[inputs.chamber_b]\nain = 1", "[inputs.chamber_b]\nain = 0");
  const std::string message = error_of(text);
  EXPECT_NE(message.find("[inputs.chamber_b] ain"), std::string::npos) << message;
  EXPECT_NE(message.find("already chamber_a's input"), std::string::npos) << message;
}

TEST(RigProfile, ALineThatCannotCarryPwmIsRefused) {
  const std::string message = error_of(replaced(paper_rig_profile_text(), "inlet_a = 2", "inlet_a = 1"));
  EXPECT_NE(message.find("[valves] inlet_a: DIO1 cannot carry PWM"), std::string::npos) << message;
}

TEST(RigProfile, ACalibrationMappingTheValidRangeToNonsenseIsRefused) {
  // A gain in mbar per volt: 9.9 V would read 9901 bar.
  const std::string text = replaced(paper_rig_profile_text(),
                                    "[inputs.supply]\nain = 2\npart = \"Buerkert 8230 pressure transmitter, 0-10 bar "
                                    "relative, 0-10 V\"\nrange_V = 10.0\ngain_per_V = 1.0",
                                    "[inputs.supply]\nain = 2\npart = \"Buerkert 8230 pressure transmitter, 0-10 bar "
                                    "relative, 0-10 V\"\nrange_V = 10.0\ngain_per_V = 1000.0");
  const std::string message = error_of(text);
  EXPECT_NE(message.find("bad.toml: [inputs.supply] gain_per_V"), std::string::npos) << message;
  EXPECT_NE(message.find("outside anything a supply sensor can read"), std::string::npos) << message;
}

TEST(RigProfile, ValidVoltagesOutsideTheInputRangeAreRefused) {
  const std::string text = replaced(paper_rig_profile_text(), "volts_max_V = 1.5", "volts_max_V = 11.0");
  EXPECT_NE(error_of(text).find("[inputs.temperature] volts_max_V"), std::string::npos) << error_of(text);
}

TEST(RigProfile, UnknownKeysMissingValvesAndBadTypesAreRefused) {
  EXPECT_NE(error_of("colour = \"red\"\n" + paper_rig_profile_text()).find("bad.toml: colour: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(paper_rig_profile_text() + "\ninlet_c = 0\n").find("[valves] inlet_c: unknown valve"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(paper_rig_profile_text(), "outlet_b = 5\n", "")).find("[valves] outlet_b: missing"),
            std::string::npos);
  EXPECT_NE(error_of(replaced(paper_rig_profile_text(), "ain = 4", "ain = \"four\""))
                .find("[inputs.temperature] ain: expected a whole number"),
            std::string::npos);
  EXPECT_NE(error_of("name = [").find("bad.toml:1"), std::string::npos) << error_of("name = [");
}

TEST(RigProfile, AMissingFileIsOneLine) {
  try {
    load_rig_profile("/nonexistent/rig.toml");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("rig profile /nonexistent/rig.toml: ", 0), 0u) << error.what();
  }
}

TEST(RigProfile, AFifoIsRefusedWithoutWaiting) {
  const std::string fifo = "/tmp/bellows-rig-profile-fifo-" + std::to_string(::getpid());
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    load_rig_profile(fifo);  // nobody writes: a blocking open would hang here
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("FIFO"), std::string::npos) << error.what();
  }
  ::unlink(fifo.c_str());
}

TEST(RigProfile, AnIdentifiedModelIsRead) {
  const std::string text =
      paper_rig_profile_text() + "\n[model]\nkappa_rad_per_bar = 6.5\nomega0_rad_per_s = 12.0\ndamping = 0.4\n";
  const RigProfile p = parse_rig_profile(text, "rig.toml");
  ASSERT_TRUE(p.model.has_value());
  EXPECT_DOUBLE_EQ(p.model->kappa_rad_per_bar, 6.5);
  EXPECT_NE(error_of(paper_rig_profile_text() + "\n[model]\ndamping = -1\n").find("[model] damping"),
            std::string::npos);
}

// What the first day learns goes into the profile file: only the keys concerned change (comments
// and everything else stay), the result is a valid profile, and a value that would make it invalid
// leaves the file as it was.
TEST(TomlKeyEdit, SetsKeysInPlaceAddsMissingOnesAndKeepsComments) {
  const std::string text =
      "# my rig\nname = \"r\"  # its name\nangle_zero_rad = 0.0\n\n[valves]\ninlet_a = 2\n\n[model]\n# fitted\ndamping "
      "= 0.3\n";
  const std::string top =
      with_table_values(text, "", {{"angle_zero_rad", "0.25"}, {"pwm_frequency_hz", "100.0"}}, "why");
  EXPECT_NE(top.find("angle_zero_rad = 0.25  # why\n"), std::string::npos) << top;
  EXPECT_EQ(top.find("angle_zero_rad = 0.0"), std::string::npos) << top;
  EXPECT_LT(top.find("pwm_frequency_hz = 100.0"), top.find("[valves]"))
      << "a top-level key goes before the first table\n"
      << top;
  EXPECT_NE(top.find("# my rig\nname = \"r\"  # its name\n"), std::string::npos) << top;
  const std::string model = with_table_values(text, "model", {{"damping", "0.4"}, {"kappa_rad_per_bar", "7.5"}}, "fit");
  EXPECT_NE(model.find("[model]\nkappa_rad_per_bar = 7.5  # fit\n# fitted\ndamping = 0.4  # fit\n"), std::string::npos)
      << model;
  const std::string added = with_table_values("name = \"r\"\n", "model", {{"damping", "0.4"}}, "fit");
  EXPECT_EQ(added, "name = \"r\"\n\n[model]\ndamping = 0.4  # fit\n");
  EXPECT_TRUE(has_table_header(text, "valves"));
  EXPECT_FALSE(has_table_header("[valves.x]\n", "valves"));
  EXPECT_EQ(toml_number(2.0), "2.0");
  EXPECT_EQ(toml_number(-0.125), "-0.125");
}

std::string profile_copy(const std::string& name) {
  const std::string path = "/tmp/bellows-profile-" + std::to_string(::getpid()) + "-" + name + ".toml";
  write_file_atomic(path, paper_rig_profile_text());
  return path;
}

// The model the learning uses (app/learning_model): the rig profile's identified one when it has
// one, else the configuration's; a configuration's own model that the profile's replaces is said.
TEST(LearningModel, TheRigProfilesIdentifiedModelIsUsedWhenItHasOne) {
  const std::string with_model = profile_copy("with-model");
  write_rig_profile_model(with_model, ModelParameters{6.5, 12.0, 0.4, 0.0});
  Configuration config;
  config.model.volume_gain_per_rad = 0.2;
  const LearningModel chosen = choose_learning_model(config, {"t7", "", "127.0.0.1:5020", with_model});
  EXPECT_EQ(chosen.source, "rig_profile");
  EXPECT_EQ(chosen.rig_profile, "paper-rig");
  EXPECT_DOUBLE_EQ(chosen.model.kappa_rad_per_bar, 6.5);
  EXPECT_DOUBLE_EQ(chosen.model.omega0_rad_per_s, 12.0);
  EXPECT_DOUBLE_EQ(chosen.model.damping, 0.4);
  EXPECT_DOUBLE_EQ(chosen.model.volume_gain_per_rad, 0.2) << "volume_gain stays the configuration's";
  EXPECT_TRUE(chosen.note.empty()) << "the configuration had the defaults: nothing replaced";
  EXPECT_EQ(learning_model_line(chosen),
            "learning with the rig profile paper-rig's [model] (kappa 6.5, omega0 12, damping 0.4)");
  EXPECT_EQ(learning_model_json(chosen)["source"], "rig_profile");
  EXPECT_EQ(learning_model_json(chosen)["kappa_rad_per_bar"], 6.5);

  config.model.kappa_rad_per_bar = 8.2;  // e.g. an earlier `identify --write-model lab.toml`
  const LearningModel replacing = choose_learning_model(config, {"t7", "", "127.0.0.1:5020", with_model});
  EXPECT_DOUBLE_EQ(replacing.model.kappa_rad_per_bar, 6.5);
  EXPECT_EQ(learning_model_line(replacing),
            "learning with the rig profile paper-rig's [model] (kappa 6.5, omega0 12, damping 0.4), "
            "not the configuration's (kappa 8.2, omega0 14.14, damping 0.31)");

  // Without a [model] in the profile (the built-in paper rig has none), and off a T7: the configuration's.
  const std::string no_model = profile_copy("no-model");
  for (const DeviceParameters& device :
       {DeviceParameters{"t7", "", "127.0.0.1:5020", ""}, DeviceParameters{"t7", "", "127.0.0.1:5020", no_model},
        DeviceParameters{"sim", "", "", ""}, DeviceParameters{"lcm", "", "", ""}}) {
    const LearningModel configured = choose_learning_model(config, device);
    EXPECT_EQ(configured.source, "configuration") << device.kind << " " << device.rig_profile;
    EXPECT_DOUBLE_EQ(configured.model.kappa_rad_per_bar, 8.2);
    EXPECT_TRUE(configured.note.empty());
    EXPECT_EQ(learning_model_line(configured), "");
    EXPECT_FALSE(learning_model_json(configured).contains("rig_profile"));
  }
  // A bad profile is the profile's one line, before anything opens.
  const std::string bad = profile_copy("bad-model");
  write_file_atomic(bad, paper_rig_profile_text() + "\n[model]\ndamping = -1\n");
  EXPECT_THROW(choose_learning_model(config, {"t7", "", "127.0.0.1:5020", bad}), InputError);
  for (const std::string& path : {with_model, no_model, bad}) std::filesystem::remove(path);
}

TEST(RigProfileWrite, TheAngleZeroIsWrittenIntoTheFile) {
  const std::string path = profile_copy("zero");
  EXPECT_TRUE(is_rig_profile_file(path));
  write_rig_profile_angle_zero(path, 0.0421);
  const RigProfile p = load_rig_profile(path);
  EXPECT_DOUBLE_EQ(p.angle_zero_rad, 0.0421);
  EXPECT_EQ(p.input(SensorRole::kAngle).gain_per_V, paper_rig_profile().input(SensorRole::kAngle).gain_per_V);
  const std::string text = read_file(path);
  EXPECT_NE(text.find("angle_zero_rad = 0.0421  # zeroed by bellows"), std::string::npos);
  EXPECT_NE(text.find("# The model identified on this rig"), std::string::npos) << "the file's comments stay";
  // A zero the profile may not hold (beyond +-pi): refused, the file unchanged.
  EXPECT_THROW(write_rig_profile_angle_zero(path, 4.0), InputError);
  EXPECT_EQ(read_file(path), text);
  ::unlink(path.c_str());
}

TEST(RigProfileWrite, TheIdentifiedModelIsWrittenIntoTheFile) {
  const std::string path = profile_copy("model");
  ModelParameters m;
  m.kappa_rad_per_bar = 6.75;
  m.omega0_rad_per_s = 12.5;
  m.damping = 0.42;
  write_rig_profile_model(path, m);
  RigProfile p = load_rig_profile(path);
  ASSERT_TRUE(p.model.has_value());
  EXPECT_DOUBLE_EQ(p.model->kappa_rad_per_bar, 6.75);
  EXPECT_DOUBLE_EQ(p.model->omega0_rad_per_s, 12.5);
  EXPECT_DOUBLE_EQ(p.model->damping, 0.42);
  m.damping = 0.5;  // a second identification replaces the first
  write_rig_profile_model(path, m);
  p = load_rig_profile(path);
  EXPECT_DOUBLE_EQ(p.model->damping, 0.5);
  EXPECT_EQ(read_file(path).find("damping = 0.42"), std::string::npos);
  ::unlink(path.c_str());
}

TEST(RigProfileWrite, AConfigurationIsNotTakenForAProfile) {
  const std::string path = "/tmp/bellows-config-" + std::to_string(::getpid()) + ".toml";
  write_file_atomic(path, "[model]\nkappa = 7.0\n[valves_note]\n");
  EXPECT_FALSE(is_rig_profile_file(path));
  ::unlink(path.c_str());
}

TEST(T7Pwm, TheClockFor200HzAndItsDutyCycles) {
  const t7::PwmClock clock = t7::pwm_clock_for(200.0);
  EXPECT_EQ(clock.divisor, 1u);
  EXPECT_EQ(clock.roll, 400000u);  // 80 MHz / 200 Hz
  EXPECT_DOUBLE_EQ(clock.frequency_hz(), 200.0);
  EXPECT_EQ(clock.config_a(0.25), 100000u);
  EXPECT_EQ(clock.config_a(1.0), 399999u);  // fully open: roll - 1, the most a T7 accepts (LabJack error 2565)
  EXPECT_EQ(clock.config_a(-0.5), 0u);
  EXPECT_EQ(clock.config_a(NAN), 0u);
  EXPECT_DOUBLE_EQ(clock.duty(100000u), 0.25);
  EXPECT_DOUBLE_EQ(clock.duty(399999u), 1.0);  // low for one count of 400000: open
  EXPECT_DOUBLE_EQ(clock.duty(500000u), 1.0);  // beyond the roll value: always high
  // Slow enough to need a divisor: 80e6 / 0.01 Hz does not fit 32 bits at divisor 1.
  const t7::PwmClock slow = t7::pwm_clock_for(0.01);
  EXPECT_GT(slow.divisor, 1u);
  EXPECT_NEAR(slow.frequency_hz(), 0.01, 1e-6);
}

}  // namespace
}  // namespace bellows
