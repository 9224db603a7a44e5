// ISO 6358 mass flow through a pneumatic valve. The simulated plant uses it as its truth and the
// pressure controller inverts it with its own nominal parameters.
#pragma once

#include <algorithm>
#include <cmath>

namespace bellows {

/// Flow function psi(r) of ISO 6358 for the pressure ratio r = p_down / p_up in [0, 1]:
/// 1 when choked (r <= b), an elliptic fall to 0 at r = 1 otherwise.
inline double iso6358_flow_function(double pressure_ratio, double critical_ratio) {
  const double r = std::clamp(pressure_ratio, 0.0, 1.0);
  if (r <= critical_ratio) return 1.0;
  const double x = (r - critical_ratio) / (1.0 - critical_ratio);
  return std::sqrt(std::max(0.0, 1.0 - x * x));
}

/// Mass flow (kg/s) from the upstream to the downstream side of one open valve, signed:
/// positive from `from_Pa` to `to_Pa`, negative when the pressure difference reverses.
inline double iso6358_mass_flow_kg_per_s(double from_Pa, double to_Pa, double conductance_m3_per_sPa,
                                         double critical_ratio, double reference_density_kg_per_m3) {
  const bool forward = from_Pa >= to_Pa;
  const double up = forward ? from_Pa : to_Pa;
  const double down = forward ? to_Pa : from_Pa;
  if (up <= 0.0) return 0.0;
  const double magnitude =
      conductance_m3_per_sPa * up * reference_density_kg_per_m3 * iso6358_flow_function(down / up, critical_ratio);
  return forward ? magnitude : -magnitude;
}

}  // namespace bellows
