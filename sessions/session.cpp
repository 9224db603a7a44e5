#include "sessions/session.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>

namespace bellows {

std::string program_version() { return BELLOWS_VERSION; }

std::string utc_now() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  const auto millis = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm utc{};
  ::gmtime_r(&seconds, &utc);
  char stamp[40];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", &utc);
  char out[48];
  std::snprintf(out, sizeof out, "%s.%03dZ", stamp, static_cast<int>(millis));
  return out;
}

std::string rig_profile_of(const SessionManifest& manifest) {
  const auto profile = manifest.device_info.find("rig_profile");
  return profile != manifest.device_info.end() && profile->is_string() ? profile->get<std::string>() : std::string();
}

}  // namespace bellows
