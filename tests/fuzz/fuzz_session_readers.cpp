// libFuzzer target for everything that reads session files: the manifest (JSON), the iteration
// samples and telemetry, the trajectory, a fault's black box and the generic numeric CSV reader. The first byte picks
// the reader; the rest is the file. Any input may be refused with an InputError, nothing else:
// no crash, no other exception, no sanitizer report. A manifest that is accepted must also
// survive writing and reading again unchanged.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "engine/base/errors.hpp"
#include "sessions/black_box_file.hpp"
#include "sessions/csv_table.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/manifest_json.hpp"

namespace {

// The short test trajectory's shape: 25 learning samples at 50 Hz, 4 ticks per sample.
constexpr int kSamples = 25;
constexpr double kSampleTime_s = 0.02;
constexpr int kTicksPerSample = 4;
constexpr double kTick_s = 0.005;

void read_manifest(std::string_view text) {
  const bellows::SessionManifest manifest = bellows::parse_manifest(text, "fuzz");
  const std::string written = bellows::format_manifest(manifest);
  if (bellows::format_manifest(bellows::parse_manifest(written, "fuzz")) != written) __builtin_trap();
}

// A black box that is accepted must also survive writing and reading again unchanged.
void read_black_box(std::string_view text) {
  constexpr int kTicks = 3;
  const std::string written = bellows::format_black_box_csv(bellows::parse_black_box_csv(text, "fuzz", kTicks));
  if (bellows::format_black_box_csv(bellows::parse_black_box_csv(written, "fuzz", kTicks)) != written) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    bellows::IterationData iteration;
    switch (data[0] % 6) {
      case 0:
        read_manifest(text);
        break;
      case 1:
        bellows::parse_samples_csv(text, "fuzz", kSamples, kSampleTime_s, iteration);
        break;
      case 2:
        iteration.record.prepare(kSamples, kTicksPerSample);  // one joint, as the samples file gives
        bellows::parse_telemetry_csv(text, "fuzz", kSamples, kTicksPerSample, kTick_s, iteration);
        break;
      case 3:
        bellows::parse_trajectory_csv_file(text, "fuzz", "fuzz", kSamples, kSampleTime_s, bellows::TrajectoryLimits{});
        break;
      case 5:
        read_black_box(text);
        break;
      default:
        bellows::parse_csv(text, {"time_s", "angle_deg", "u_bar"}, "fuzz");
        break;
    }
  } catch (const bellows::InputError&) {
    // Refused with a clear error: what bad input must get.
  }
  return 0;
}
