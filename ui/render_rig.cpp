// The Rig screen: the first day at the bench. Left, the inputs live (raw volts beside calibrated
// values where the device has volts; the simulated arm has none, so it shows what the engine
// reads); right, the valve test's verdicts, one line per valve, and the link's health.
#include <algorithm>

#include "ui/render_parts.hpp"

namespace bellows::ui::detail {

void render_rig(const ConsoleState& s, Canvas& c, const Rect& body) {
  const Glyphs g = Glyphs::for_unicode(s.unicode);
  const RigView& rig = s.rig;
  const int left_width = std::max(40, body.width * 2 / 5);
  const Rect inputs{body.x, body.y, left_width, body.height};
  std::string title = "Inputs: " + s.device.name;
  if (!rig.where.empty()) title += " (" + rig.where + ")";
  c.frame(inputs, g, title);
  Rect in = inner(inputs);
  int y = in.y;
  if (!rig.rig_profile.empty()) c.put(in.x + 1, y++, "rig profile " + rig.rig_profile, Role::kDim, false, in.right());
  const SensorReading& r = s.live.reading;
  if (rig.raw.count > 0) {
    c.put(in.x + 1, y++, fit("input", 14) + fit("raw V", 10) + "value", Role::kTitle, true, in.right());
    for (int i = 0; i < rig.raw.count && y < in.bottom(); ++i) {
      const RawInput& input = rig.raw.inputs[static_cast<std::size_t>(i)];
      c.put(in.x + 1, y++,
            fit(input.name, 14) + fit(number("%.4f", input.volts), 10) + number("%.4f ", input.value) + input.unit,
            Role::kNormal, false, in.right());
    }
  } else {
    c.put(in.x + 1, y++, "no volts: " + s.device.name + " reports calibrated values only", Role::kDim, false,
          in.right());
    c.put(in.x + 1, y++, fit("input", 14) + "value (as the engine reads it)", Role::kTitle, true, in.right());
    const std::pair<const char*, std::string> rows[] = {
        {"angle", number("%.3f deg", to_deg(r.joint[0].angle_rad))},
        {"chamber A", number("%.4f bar", r.joint[0].chamber_bar[0])},
        {"chamber B", number("%.4f bar", r.joint[0].chamber_bar[1])},
        {"supply", number("%.4f bar", r.supply_bar)},
        {"temperature", number("%.2f K", r.temperature_K)},
    };
    for (const auto& [name, value] : rows) {
      if (y >= in.bottom()) break;
      c.put(in.x + 1, y++, fit(name, 14) + (s.live_valid ? value : "no data"), Role::kNormal, false, in.right());
    }
  }
  if (y + 2 < in.bottom()) {
    ++y;
    c.put(in.x + 1, y++, "link", Role::kTitle, true, in.right());
    c.put(in.x + 1, y++, s.device.status, s.device.ok ? Role::kGood : Role::kWarning, false, in.right());
  }

  const Rect valves{inputs.right(), body.y, body.width - left_width, body.height};
  c.frame(valves, g, "Valve test (v starts it; Space vents)");
  in = inner(valves);
  y = in.y;
  if (rig.valves.empty()) {
    c.put(in.x + 1, y++, "Not run yet. v pulses each valve alone and checks that the right", Role::kDim, false,
          in.right());
    c.put(in.x + 1, y++, "chamber moves the right way: swapped tubes or wires, a dead valve", Role::kDim, false,
          in.right());
    c.put(in.x + 1, y++, "and no supply are each named.", Role::kDim, false, in.right());
    return;
  }
  c.put(in.x + 1, y++, rig.test_progress, rig.test_running ? Role::kRunning : Role::kTitle, true, in.right());
  ++y;
  for (const RigView::ValveLine& line : rig.valves) {
    if (y >= in.bottom()) break;
    const char* verdict = line.pass ? "pass" : (line.tested || line.text != "waiting" ? "FAIL" : "    ");
    const Role role = line.pass ? Role::kGood : (line.tested || line.text != "waiting" ? Role::kFault : Role::kDim);
    int x = c.put(in.x + 1, y, fit(line.valve, 10), Role::kNormal, true);
    x = c.put(x, y, fit(verdict, 6), role, true);
    for (const std::string& part : wrap(line.text, std::max(10, in.right() - x))) {
      if (y >= in.bottom()) break;
      c.put(x, y++, part, line.pass ? Role::kDim : Role::kNormal, false, in.right());
    }
  }
}

}  // namespace bellows::ui::detail
