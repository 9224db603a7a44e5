// libFuzzer target for the TOML configuration loader (app/config_file). Any input may be refused
// with an InputError, nothing else: no crash (a deeply nested file once overflowed toml++'s stack),
// no other exception, no sanitizer report, no hang or huge allocation. A configuration that is
// accepted must hold only values inside the parameter table's ranges, and survive printing as TOML
// and loading again unchanged.
#include <cstddef>
#include <cstdint>
#include <string>

#include "app/config_file.hpp"
#include "engine/base/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  bellows::Configuration config;
  try {
    bellows::apply_config_toml(text, "fuzz.toml", config);
  } catch (const bellows::InputError&) {
    return 0;
  }
  bellows::validate_configuration(config);  // throws (and so fails) if the loader let a bad value in
  const std::string written = bellows::config_to_toml(config);
  bellows::Configuration again;
  bellows::apply_config_toml(written, "fuzz-written.toml", again);
  if (bellows::config_to_toml(again) != written) __builtin_trap();
  return 0;
}
