// Set-point mapping (spec section 3): the total input u_tot (bar) becomes antagonistic chamber
// set points, each clamped to [p0, p_max]:  pA = clamp(p0 + u), pB = clamp(p0 - u).
#pragma once

#include <algorithm>

namespace bellows {

struct ChamberSetpoints {
  double a_bar = 0.0;
  double b_bar = 0.0;
  int saturation_sign = 0;  // +1 / -1 when u_tot lies beyond what the clamp lets through
};

inline ChamberSetpoints map_setpoints(double u_total_bar, double ambient_bar, double p_max_bar) {
  ChamberSetpoints s;
  s.a_bar = std::clamp(ambient_bar + u_total_bar, ambient_bar, p_max_bar);
  s.b_bar = std::clamp(ambient_bar - u_total_bar, ambient_bar, p_max_bar);
  const double span = p_max_bar - ambient_bar;
  s.saturation_sign = u_total_bar > span ? 1 : (u_total_bar < -span ? -1 : 0);
  return s;
}

}  // namespace bellows
