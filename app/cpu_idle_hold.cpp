#include "app/cpu_idle_hold.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>

namespace bellows {

CpuIdleHold::CpuIdleHold(bool wanted, int max_wakeup_us, const std::string& driver_path)
    : max_wakeup_us_(max_wakeup_us) {
  if (!wanted) return;
  std::string driver;
  if (std::ifstream file(driver_path); !(file >> driver) || driver == "none") {
    why_not_ = "no cpuidle driver (" + driver_path + ": " + (driver.empty() ? "missing" : driver) +
               "): idle cores halt whatever is asked";
    return;
  }
  fd_ = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  if (fd_ < 0) {
    why_not_ = "/dev/cpu_dma_latency cannot be opened (no permission)";
    return;
  }
  const auto value = static_cast<std::int32_t>(max_wakeup_us);
  if (::write(fd_, &value, sizeof value) != static_cast<ssize_t>(sizeof value)) {
    ::close(fd_);
    fd_ = -1;
    why_not_ = "/dev/cpu_dma_latency refused the limit";
  }
}

CpuIdleHold::~CpuIdleHold() {
  if (fd_ >= 0) ::close(fd_);  // ends the request
}

std::optional<int> CpuIdleHold::held_us() const {
  if (fd_ < 0) return std::nullopt;
  return max_wakeup_us_;
}

}  // namespace bellows
