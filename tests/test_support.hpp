// Small checks many tests share. Test files are compiled in unity batches (tests/CMakeLists.txt):
// a helper two files need lives here once, not in each file's anonymous namespace.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <functional>
#include <string>

#include "engine/model/arm_model.hpp"
#include "engine/control/device.hpp"
#include "engine/base/errors.hpp"

namespace bellows::testing {

/// Whether this build runs under a sanitizer (tests/CMakeLists.txt defines BELLOWS_SANITIZED): a
/// test whose cost grows fast with its size checks the largest sizes in the plain build only.
#ifdef BELLOWS_SANITIZED
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

/// What `action` threw as an InputError, or "(no error)".
inline std::string error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no error)";
}

/// Inlets shut and outlets open: the safe state (of one joint's valves, of every joint commanded).
inline bool vented(const JointValves& v) {
  return v.inlet_duty[0] == 0.0 && v.inlet_duty[1] == 0.0 && v.outlet_duty[0] == 1.0 && v.outlet_duty[1] == 1.0;
}
inline bool vented(const ValveCommand& c) {
  for (int j = 0; j < c.joint_count; ++j) {
    if (!vented(c.joint[static_cast<std::size_t>(j)])) return false;
  }
  return true;
}

/// No byte of `text` outside 7-bit ASCII.
inline bool ascii_only(const std::string& text) {
  for (unsigned char c : text) {
    if (c >= 0x80) return false;
  }
  return true;
}

/// Reads `fd` until `text` has appeared (or, with an empty `text`, until end of file or an error).
inline std::string read_until(int fd, const std::string& text) {
  std::string out;
  char buffer[1024];
  while (text.empty() || out.find(text) == std::string::npos) {
    const ssize_t got = ::read(fd, buffer, sizeof buffer);
    if (got <= 0) break;
    out.append(buffer, static_cast<std::size_t>(got));
  }
  return out;
}

/// The paper's model (the defaults), sampled at the learning rate of 50 Hz.
inline DiscreteArmModel paper_model() { return discretize_arm_model(ModelParameters{}, 0.02); }

}  // namespace bellows::testing
