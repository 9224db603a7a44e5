#include <gtest/gtest.h>

#include "app/config_file.hpp"

#include <fstream>
#include <sstream>
#include "engine/base/errors.hpp"
#include "tests/config_test_support.hpp"

namespace bellows {
namespace {

TEST(ConfigFile, DefaultsAreTheSpecsValues) {
  const Configuration c;
  EXPECT_DOUBLE_EQ(c.plant.kappa_rad_per_bar, 7.91);
  EXPECT_DOUBLE_EQ(c.plant.omega0_rad_per_s, 14.14);
  EXPECT_DOUBLE_EQ(c.plant.damping, 0.31);
  EXPECT_DOUBLE_EQ(c.plant.volume_l, 0.45);
  EXPECT_DOUBLE_EQ(c.plant.valve_conductance_m3_per_sPa, 3.0e-9);
  EXPECT_DOUBLE_EQ(c.plant.creep_tau_s, 0.8);
  EXPECT_DOUBLE_EQ(c.controller.k_ff, 0.4);
  EXPECT_DOUBLE_EQ(c.controller.tau_p_s, 0.02);
  EXPECT_DOUBLE_EQ(c.controller.p_max_bar, 1.4);
  EXPECT_DOUBLE_EQ(c.ilc.s, 0.1);
  EXPECT_DOUBLE_EQ(c.ilc.w, 2e-5);
  EXPECT_NO_THROW(validate_configuration(c));
}

TEST(ConfigFile, InterfaceKeysAreAllKnown) {
  Configuration c;
  apply_config_toml(R"(
[plant]
kappa = 7.0
omega0 = 12.0
damping = 0.3
volume_l = 0.5
volume_gain = 0.3
valve_conductance = 4e-9
valve_critical_ratio = 0.38
creep_gain = 0.2
creep_tau_s = 1.0
supply_bar = 3.5
encoder_resolution_deg = 0.05
pressure_noise_bar = 0.001
[model]
kappa = 7.5
omega0 = 13.0
damping = 0.32
[controller]
k_ff = 0.35
k_p = 0.25
k_i = 0.2
k_d = 0.02
tau_p_s = 0.03
p_max_bar = 1.5
[ilc]
m = 2.0
s = 0.2
w = 1e-5
)",
                    "test.toml", c);
  EXPECT_DOUBLE_EQ(c.plant.kappa_rad_per_bar, 7.0);
  EXPECT_DOUBLE_EQ(c.plant.valve_critical_ratio, 0.38);
  EXPECT_DOUBLE_EQ(c.model.kappa_rad_per_bar, 7.5);
  EXPECT_DOUBLE_EQ(c.controller.k_i_per_s, 0.2);
  EXPECT_DOUBLE_EQ(c.controller.p_max_bar, 1.5);
  EXPECT_DOUBLE_EQ(c.ilc.w, 1e-5);
  EXPECT_DOUBLE_EQ(c.plant.pressure_noise_bar, 0.001);
}

using testing::expect_config_refused;

TEST(ConfigFile, RejectsBadConfigurations) {
  expect_config_refused("[plant]\nkapa = 7.0\n", "unknown key");
  expect_config_refused("[plants]\nkappa = 7.0\n", "unknown section");
  expect_config_refused("[plant]\nkappa = \"seven\"\n", "expected a number");
  expect_config_refused("[controller]\nfilter_samples = 2.5\n", "expected a whole number");
  expect_config_refused("[controller]\ntau_p_s = 0.0\n", "must be in (0, ");
  expect_config_refused("[plant]\ncreep_tau_s = -0.8\n", "must be in (0, ");
  expect_config_refused("[controller]\np_max_bar = 1.0\n", "above ambient");
  expect_config_refused("[plant]\nkappa = nan\n", "finite");
  expect_config_refused("[plant\nkappa = 7\n", "lab.toml:");
  expect_config_refused("plant = 3\n", "must be a table");
  // The TOML parser's own refusals name the key too, not only the line (issue 24).
  expect_config_refused("[controller]\nfilter_samples = 18446744073709551617\n", "[controller] filter_samples: ");
  expect_config_refused("[controller]\n  # a note\nfilter_samples = 18446744073709551617\n",
                        "[controller] filter_samples: ");
}

TEST(ConfigFile, ArmPresetChoosesTheChainAndIsOneJointWhenAbsent) {
  Configuration c;
  EXPECT_EQ(c.arm.preset, "");  // absent: the single joint of [plant]
  apply_config_toml("[arm]\npreset = \"arm3\"\n", "arm3.toml", c);
  EXPECT_EQ(c.arm.preset, "arm3");
  apply_config_toml("[arm]\npreset = \"arm2\"\n", "arm2.toml", c);
  EXPECT_EQ(c.arm.preset, "arm2");
  expect_config_refused("[arm]\npreset = \"arm7\"\n",
                        "[arm] preset = 'arm7': unknown arm (known: arm2, arm3; empty: one joint)");
  expect_config_refused("[arm]\npreset = 2\n", "[arm] preset");
  expect_config_refused("[arm]\nlinks = 2\n", "unknown key");
  // A chain of its own keys: the joints, each link's keys in its own section.
  Configuration own;
  apply_config_toml("[arm]\njoints = 3\ngravity = 0\n[arm_joint3]\nmass_kg = 0.06\nbellows_scale = 1.5\n", "own.toml",
                    own);
  EXPECT_EQ(own.arm.joints, 3);
  EXPECT_EQ(own.arm.gravity, 0);
  EXPECT_EQ(own.arm.joint[2].mass_kg, 0.06);
  EXPECT_EQ(own.arm.joint[2].bellows_scale, 1.5);
  EXPECT_EQ(own.arm.joint[1].mass_kg, ArmJointParameters{}.mass_kg);
  EXPECT_EQ(own.arm.name(), "[arm] joints = 3");
  expect_config_refused("[arm_joint5]\nmass_kg = 1\n", "unknown section [arm_joint5]");
  expect_config_refused("[arm_joint1]\nmass_kg = -1\n", "[arm_joint1] mass_kg");
  expect_config_refused("[arm]\ngravity = 2\n", "[arm] gravity");
}

TEST(ConfigFile, EachJointHasItsOwnAngleLimitDefaultingToTheSafetyLimit) {
  Configuration c;
  // A joint guarded more tightly than the others: every trajectory's range below it.
  apply_config_toml(
      "[arm]\npreset = \"arm2\"\n[safety]\nangle_limit_deg = 92\n[trajectory]\nmax_abs_angle_deg = 60\n"
      "[arm_joint2]\nangle_limit_deg = 70\n",
      "arm2.toml", c);
  EXPECT_EQ(c.safety.angle_limit_deg_of(0), 92.0) << "no key of its own: [safety] angle_limit_deg";
  EXPECT_EQ(c.safety.angle_limit_deg_of(1), 70.0);
  // One joint ([plant]'s) is joint 1: its own limit too.
  Configuration one;
  apply_config_toml("[arm_joint1]\nangle_limit_deg = 93.5\n", "one.toml", one);
  EXPECT_EQ(one.safety.angle_limit_deg_of(0), 93.5);
  // The same rules as [safety] angle_limit_deg: above every trajectory, within the rig's range.
  expect_config_refused("[arm_joint2]\nangle_limit_deg = 90\n",
                        "[arm_joint2] angle_limit_deg = 90: must be above [trajectory] max_abs_angle_deg = 90");
  expect_config_refused("[arm_joint3]\nangle_limit_deg = 120\n",
                        "[arm_joint3] angle_limit_deg = 120: must not be above [lcm] rig_angle_limit_deg = 100");
  expect_config_refused("[arm_joint1]\nangle_limit_deg = -5\n",
                        "[arm_joint1] angle_limit_deg = -5: must be in [0, 180]");
  apply_config_toml("[lcm]\nrig_angle_limit_deg = 130\n[arm_joint4]\nangle_limit_deg = 120\n", "wide.toml", c);
  EXPECT_EQ(c.safety.angle_limit_deg_of(3), 120.0);
}

TEST(ConfigFile, RoundTripsThroughToml) {
  Configuration c;
  c.plant.kappa_rad_per_bar = 6.5;
  c.controller.filter_samples = 6;
  c.ilc.law = "noilc-dense";
  Configuration back;
  apply_config_toml(config_to_toml(c), "roundtrip", back);
  EXPECT_DOUBLE_EQ(back.plant.kappa_rad_per_bar, 6.5);
  EXPECT_EQ(back.controller.filter_samples, 6);
  EXPECT_EQ(back.ilc.law, "noilc-dense");
}

}  // namespace
}  // namespace bellows

namespace bellows {
namespace {

/// docs/configuration.md, or "" when it cannot be read.
std::string configuration_doc() {
  std::ifstream in(std::string(BELLOWS_SOURCE_DIR) + "/docs/configuration.md");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(ConfigFile, EveryKeyIsDocumented) {
  const std::string doc = configuration_doc();
  ASSERT_FALSE(doc.empty()) << "docs/configuration.md missing";
  for (const ParameterBinding& b : parameter_bindings()) {
    const auto section = doc.find("## [" + b.section + "]");
    ASSERT_NE(section, std::string::npos) << "section [" << b.section << "] is not documented";
    const auto next_section = doc.find("\n## ", section + 1);
    const auto key = doc.find("| `" + b.key + "` |", section);
    EXPECT_TRUE(key != std::string::npos && key < next_section)
        << "[" << b.section << "] " << b.key << " is not documented";
  }
}

// The key reference is generated (scripts/gen-config-docs.sh): a key whose description, default or range
// changed without the reference being regenerated fails here, not in a reader's hands.
TEST(ConfigFile, TheKeyReferenceIsWhatBellowsConfigPrints) {
  const std::string doc = configuration_doc();
  const auto reference = doc.find("## [");
  ASSERT_NE(reference, std::string::npos) << "docs/configuration.md missing or without its key reference";
  std::string printed = config_to_markdown(Configuration{});
  ASSERT_EQ(printed.rfind("\n## [", 0), 0u);
  printed.erase(0, 1);  // the script drops the leading empty line
  EXPECT_EQ(doc.substr(reference), printed) << "run scripts/gen-config-docs.sh build-test/app/bellows";
}

}  // namespace
}  // namespace bellows

namespace bellows {
namespace {

// `bellows config` is a file a person starts from: every value reads back exactly, in its shortest
// form, sections in the documented order, each key under its meaning and unit.
TEST(ConfigFile, PrintedConfigurationIsExactShortAndCommented) {
  Configuration c;
  c.plant.kappa_rad_per_bar = 0.4;
  c.ilc.s = 0.1 + 0.2;  // 0.30000000000000004: needs all its digits to read back exactly
  c.device.t7_address = "10.0.0.2:502 \"quoted\"";
  const std::string toml = config_to_toml(c);
  Configuration back;
  apply_config_toml(toml, "printed", back);
  Configuration original = c, reread = back;
  for (const ParameterBinding& b : parameter_bindings()) {
    if (b.text) {
      EXPECT_EQ(*b.text(reread), *b.text(original)) << b.section << " " << b.key;
    } else if (b.integer) {
      EXPECT_EQ(*b.integer(reread), *b.integer(original)) << b.section << " " << b.key;
    } else {
      EXPECT_EQ(*b.real(reread), *b.real(original)) << b.section << " " << b.key;  // exactly, not nearly
    }
    EXPECT_NE(toml.find(b.description), std::string::npos) << b.key;
    if (!b.unit.empty()) {
      EXPECT_NE(toml.find("[" + b.unit + "]"), std::string::npos) << b.key;
    }
  }
  EXPECT_NE(toml.find("\nkappa = 0.4\n"), std::string::npos) << toml;
  EXPECT_NE(toml.find("0.30000000000000004"), std::string::npos);
  // No 17-digit noise on the defaults.
  const std::string defaults = config_to_toml(Configuration{});
  EXPECT_EQ(defaults.find("0000000000"), std::string::npos) << defaults;
  EXPECT_EQ(defaults.find("9999999999"), std::string::npos) << defaults;
  // Sections in the table's order.
  std::size_t last = 0;
  std::string previous;
  for (const ParameterBinding& b : parameter_bindings()) {
    if (b.section == previous) continue;
    previous = b.section;
    const std::size_t at = defaults.find("\n[" + b.section + "]\n");
    ASSERT_NE(at, std::string::npos) << b.section;
    EXPECT_GE(at, last) << b.section;
    last = at;
  }
}

}  // namespace
}  // namespace bellows
