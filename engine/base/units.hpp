// Angle units: the engine computes in radians, people read degrees. One definition for every file
// (unity builds put several files in one translation unit, where local copies would clash).
#pragma once

#include <numbers>

namespace bellows {

inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;
inline constexpr double kPaPerBar = 1e5;

}  // namespace bellows
