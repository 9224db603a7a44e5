#include "app/t7_wiring.hpp"

#include "app/rig_profile_file.hpp"
#include "app/signals.hpp"
#include "engine/base/errors.hpp"

namespace bellows {

void parse_host_port(const std::string& address, int default_port, std::string& host, int& port,
                     const std::string& option, int lowest_port) {
  const auto bad = [&](const std::string& why) { throw InputError(option + " '" + address + "': " + why); };
  if (address.empty()) bad("an address is needed: HOST[:PORT]");
  std::string port_text;
  if (address.front() == '[') {  // [v6 address]:port
    const auto close = address.find(']');
    if (close == std::string::npos) bad("no closing ]");
    host = address.substr(1, close - 1);
    if (close + 1 < address.size()) {
      if (address[close + 1] != ':') bad("expected :PORT after ]");
      port_text = address.substr(close + 2);
    }
  } else if (const auto colon = address.rfind(':'); colon != std::string::npos && address.find(':') == colon) {
    host = address.substr(0, colon);
    port_text = address.substr(colon + 1);
    if (port_text.empty()) bad("a port after ':' is needed");
  } else {
    host = address;
  }
  if (host.empty()) bad("no host");
  port = default_port;
  if (!port_text.empty()) {
    std::size_t used = 0;
    int value = 0;
    try {
      value = std::stoi(port_text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != port_text.size() || value < lowest_port || value > 65535) {
      bad("the port must be a number " + std::to_string(lowest_port) + "..65535");
    }
    port = value;
  }
}

std::unique_ptr<T7Device> open_t7_device(const T7Options& options, const Configuration& config) {
  T7DeviceOptions device;
  parse_host_port(options.address, kDefaultT7Port, device.host, device.port);
  device.profile = rig_profile_or_default(options.rig_profile);  // InputError before any traffic
  device.link = config.t7;
  device.tick_s = config.timing.tick_s;
  device.realtime = options.realtime;
  device.stop = &stop_requested();  // SIGINT, SIGTERM while connecting: Cancelled, exit 128 + signal
  if (config.t7.watchdog_timeout_s < 1) throw InputError("[t7] watchdog_timeout_s must be at least 1 (whole seconds)");
  return std::make_unique<T7Device>(std::move(device));
}

}  // namespace bellows
