#include "app/rig_profile_file.hpp"

#include <fstream>
#include <sstream>

#include <toml++/toml.h>

#include "engine/base/errors.hpp"
#include "sessions/file_access.hpp"

namespace bellows {

extern const char* const kPaperRigProfileToml;  // generated from profiles/paper-rig.toml (app/CMakeLists.txt)

namespace {

class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError("rig profile " + source_ + ": " + key + ": " + what);
  }

  double number(const toml::node& node, const std::string& key) const {
    if (!node.is_number()) fail(key, "expected a number");
    return *node.value<double>();
  }
  int whole(const toml::node& node, const std::string& key) const {
    if (!node.is_integer()) fail(key, "expected a whole number");
    return static_cast<int>(*node.value<std::int64_t>());
  }
  std::string text(const toml::node& node, const std::string& key) const {
    if (!node.is_string()) fail(key, "expected a string");
    return *node.value<std::string>();
  }
  const toml::table& table(const toml::node& node, const std::string& key) const {
    if (!node.is_table()) fail(key, "expected a table");
    return *node.as_table();
  }

 private:
  std::string source_;
};

void read_input(const Reader& r, const toml::table& t, const std::string& section, SensorCalibration& c) {
  bool has_ain = false;
  for (const auto& [k, v] : t) {
    const std::string key(k.str());
    const std::string where = section + " " + key;
    if (key == "ain") {
      c.ain = r.whole(v, where);
      has_ain = true;
    } else if (key == "part") c.part = r.text(v, where);
    else if (key == "range_V") c.range_V = r.number(v, where);
    else if (key == "gain_per_V") c.gain_per_V = r.number(v, where);
    else if (key == "offset") c.offset = r.number(v, where);
    else if (key == "volts_min_V") c.volts_min_V = r.number(v, where);
    else if (key == "volts_max_V") c.volts_max_V = r.number(v, where);
    else if (key == "resolution_index") c.resolution_index = r.whole(v, where);
    else if (key == "settling_us") c.settling_us = r.number(v, where);
    else
      r.fail(where,
             "unknown key (ain, part, range_V, gain_per_V, offset, volts_min_V, volts_max_V, resolution_index, "
             "settling_us)");
  }
  if (!has_ain) r.fail(section + " ain", "missing");
}

}  // namespace

RigProfile parse_rig_profile(const std::string& toml_text, const std::string& source_name) {
  toml::table root;
  try {
    root = toml::parse(toml_text, source_name);
  } catch (const toml::parse_error& error) {
    std::ostringstream where;
    where << "rig profile " << source_name << ":" << error.source().begin.line << ":" << error.source().begin.column
          << ": " << error.description();
    throw InputError(where.str());
  }
  const Reader r(source_name);
  RigProfile p;
  p.source = source_name;
  bool has_valves = false;
  for (const auto& [k, v] : root) {
    const std::string key(k.str());
    if (key == "name") p.name = r.text(v, key);
    else if (key == "pwm_frequency_hz") p.pwm_frequency_hz = r.number(v, key);
    else if (key == "angle_zero_rad") p.angle_zero_rad = r.number(v, key);
    else if (key == "inputs") {
      for (const auto& [input_key, input] : r.table(v, "[inputs]")) {
        const std::string name(input_key.str());
        const std::string section = "[inputs." + name + "]";
        SensorCalibration* target = nullptr;
        for (SensorRole role : kSensorRoles) {
          if (name == to_string(role)) target = &p.input(role);
        }
        if (target == nullptr) r.fail(section, "unknown input (chamber_a, chamber_b, supply, angle, temperature)");
        read_input(r, r.table(input, section), section, *target);
      }
    } else if (key == "valves") {
      has_valves = true;
      std::array<bool, kValveRoleCount> seen{};
      for (const auto& [valve_key, line] : r.table(v, "[valves]")) {
        const std::string name(valve_key.str());
        bool known = false;
        for (ValveRole role : kValveRoles) {
          if (name == to_string(role)) {
            p.valve_dio[static_cast<int>(role)] = r.whole(line, "[valves] " + name);
            seen[static_cast<int>(role)] = known = true;
          }
        }
        if (!known) r.fail("[valves] " + name, "unknown valve (inlet_a, inlet_b, outlet_a, outlet_b)");
      }
      for (ValveRole role : kValveRoles) {
        if (!seen[static_cast<int>(role)]) r.fail(std::string("[valves] ") + to_string(role), "missing");
      }
    } else if (key == "model") {
      ModelParameters m;
      for (const auto& [model_key, value] : r.table(v, "[model]")) {
        const std::string name(model_key.str());
        const std::string where = "[model] " + name;
        if (name == "kappa_rad_per_bar") m.kappa_rad_per_bar = r.number(value, where);
        else if (name == "omega0_rad_per_s") m.omega0_rad_per_s = r.number(value, where);
        else if (name == "damping") m.damping = r.number(value, where);
        else if (name == "volume_gain_per_rad") m.volume_gain_per_rad = r.number(value, where);
        else r.fail(where, "unknown key (kappa_rad_per_bar, omega0_rad_per_s, damping, volume_gain_per_rad)");
      }
      p.model = m;
    } else {
      r.fail(key, "unknown key (name, pwm_frequency_hz, angle_zero_rad, [inputs.*], [valves], [model])");
    }
  }
  if (!has_valves) r.fail("[valves]", "missing");
  validate_rig_profile(p);
  return p;
}

RigProfile load_rig_profile(const std::string& path) {
  // Like a config file: a FIFO or a device is refused without blocking, and the size is bounded.
  constexpr std::size_t kMaxRigProfileBytes = 256 * 1024;
  return parse_rig_profile(read_regular_file(path, kMaxRigProfileBytes, "rig profile"), path);
}

const std::string& paper_rig_profile_text() {
  static const std::string text = kPaperRigProfileToml;
  return text;
}

RigProfile paper_rig_profile() { return parse_rig_profile(paper_rig_profile_text(), "paper-rig (built in)"); }

RigProfile rig_profile_or_default(const std::string& path) {
  return path.empty() ? paper_rig_profile() : load_rig_profile(path);
}

}  // namespace bellows
