#include "sessions/session.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>
#include <stdexcept>

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

Eigen::MatrixXd IterationData::next_corrections_bar() const {
  Eigen::MatrixXd out(next_correction_bar.size(), joints());
  out.col(0) = next_correction_bar;
  for (int joint = 1; joint < joints(); ++joint) {
    const Eigen::VectorXd& column = more_joint_next_correction_bar[static_cast<std::size_t>(joint - 1)];
    if (column.size() != out.rows())
      throw std::invalid_argument("IterationData: the joints' corrections differ in length");
    out.col(joint) = column;
  }
  return out;
}

void IterationData::set_next_corrections(const Eigen::MatrixXd& corrections_bar) {
  next_correction_bar = corrections_bar.cols() > 0 ? Eigen::VectorXd(corrections_bar.col(0)) : Eigen::VectorXd();
  more_joint_next_correction_bar.clear();
  for (Eigen::Index joint = 1; joint < corrections_bar.cols(); ++joint) {
    more_joint_next_correction_bar.emplace_back(corrections_bar.col(joint));
  }
}

std::string rig_profile_of(const SessionManifest& manifest) {
  const auto profile = manifest.device_info.find("rig_profile");
  return profile != manifest.device_info.end() && profile->is_string() ? profile->get<std::string>() : std::string();
}

}  // namespace bellows
