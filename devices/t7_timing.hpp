// How long a T7 takes to answer, as LabJack documents it (docs/labjack-t7.md has the sources):
// one command-response costs the link's overhead (T-Series datasheet appendix A-1, Table A.1.1:
// 1.0 ms over Ethernet with direct Modbus TCP) plus, for a read of analog inputs, each input's
// sample time at its resolution index (appendix A-3-2-2 "T7 Noise and Resolution"). Resolution
// index 0 means the product's default: 8 on a T7, 9 on a T7-Pro (AIN#_RESOLUTION_INDEX in
// ljm_constants.json); 9..12 exist on the Pro only (its 24-bit sigma-delta ADC). The same table
// paces t7-sim's answers and checks, before connecting, that a rig profile's read fits the tick.
#pragma once

#include <array>
#include <string>

#include "devices/rig_profile.hpp"

namespace bellows::t7 {

enum class Product { kT7, kT7Pro };
/// "T7" or "T7-Pro".
const char* to_string(Product product);

inline constexpr double kEthernetOverhead_s = 0.0010;  // appendix A-1, Table A.1.1, "No I/O - Overhead", Ethernet
inline constexpr int kMaxResolutionIndexT7 = 8;
inline constexpr int kMaxResolutionIndexT7Pro = 12;
inline constexpr int kDefaultResolutionIndexT7 = 8;
inline constexpr int kDefaultResolutionIndexT7Pro = 9;
inline constexpr double kMaxSettling_us = 50000.0;  // AIN#_SETTLING_US: "0 = Auto. Max is 50000"

/// Command-response sample time of one input (auto settling) by resolution index 1..12, seconds
/// (appendix A-3-2-2). Index 0 is not in it: see effective_resolution_index().
inline constexpr std::array<double, 13> kSampleTime_s = {
    0.0,                                                               // 0: the product default (never looked up)
    0.00004, 0.00004, 0.0001, 0.0001, 0.0002, 0.0003, 0.0006, 0.0011,  // 1..8: the 16-bit ADC
    0.0035,  0.0134,  0.0662, 0.159};                                  // 9..12: the Pro's 24-bit ADC

int max_resolution_index(Product product);
/// The index a T7 samples at: `index`, or the product default for 0.
int effective_resolution_index(int index, Product product);
/// One input's sample time: the table's at the effective index, plus an explicit settling time
/// beyond automatic (0 = auto, which the table includes).
double sample_time_s(int index, double settling_us, Product product);

/// One exchange of bellows' T7 link: the write of the duty cycles and the read of AIN0 up to the
/// highest input in use (inputs in the block that the profile does not use are set to index 1).
struct ExchangeTime {
  int inputs = 0;                              // AINs in the read block
  double sampling_s = 0.0;                     // their sample times together
  double read_s = 0.0;                         // overhead + sampling
  double exchange_s = 0.0;                     // the write's overhead + the read
  SensorRole slowest = SensorRole::kChamberA;  // the input whose key a refusal names
};
ExchangeTime exchange_time(const RigProfile& profile, Product product);

/// Refuses, in one line naming the slowest input's key, a profile whose exchange cannot be answered
/// within `limit_s` (the smaller of the tick and [t7] response_timeout_s). Checked before
/// connecting with the T7-Pro (index 0 means its slower default); InputError.
void require_exchange_fits(const RigProfile& profile, Product product, double tick_s, double response_timeout_s);

}  // namespace bellows::t7
