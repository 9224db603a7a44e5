// Configuration text that must be refused, for the configuration tests.
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "app/config_file.hpp"
#include "engine/config/configuration.hpp"
#include "engine/base/errors.hpp"

namespace bellows::testing {

/// `toml`, read as the file "lab.toml", is refused with an InputError that names the file and
/// contains `fragment`.
inline void expect_config_refused(const std::string& toml, const std::string& fragment) {
  Configuration config;
  try {
    apply_config_toml(toml, "lab.toml", config);
    ADD_FAILURE() << "accepted: " << toml;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("lab.toml"), std::string::npos) << e.what();
  }
}

}  // namespace bellows::testing
