#include "app/lcm_url.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <charconv>
#include <string_view>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {

constexpr std::size_t kMaxUrlLength = 1024;

bool whole_number_in(std::string_view text, long min, long max) {
  long value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc{} && end == text.data() + text.size() && value >= min && value <= max;
}

struct Parts {
  std::string provider, network, options;
};

Parts split(const std::string& url) {
  Parts parts;
  const auto scheme = url.find("://");
  if (scheme == std::string::npos) return parts;
  parts.provider = url.substr(0, scheme);
  const std::string rest = url.substr(scheme + 3);
  const auto question = rest.find('?');
  parts.network = rest.substr(0, question);
  if (question != std::string::npos) parts.options = rest.substr(question + 1);
  return parts;
}

// Empty when fine, else what is wrong with "address:port" of udpm.
std::string udpm_network_problem(const std::string& network) {
  if (network.empty()) return "";  // LCM's default group and port
  const auto colon = network.find(':');
  const std::string address = network.substr(0, colon);
  in_addr parsed{};
  if (inet_pton(AF_INET, address.c_str(), &parsed) != 1) return "'" + address + "' is not an IPv4 address";
  const unsigned first = ntohl(parsed.s_addr) >> 24;
  if (first < 224 || first > 239) return address + " is not a multicast address (224.0.0.0 to 239.255.255.255)";
  if (colon != std::string::npos && !whole_number_in(std::string_view(network).substr(colon + 1), 1, 65535)) {
    return "the port must be a whole number from 1 to 65535";
  }
  return "";
}

std::string udpm_options_problem(const std::string& options) {
  std::string_view rest = options;
  while (!rest.empty()) {
    const auto amp = rest.find('&');
    const std::string_view option = rest.substr(0, amp);
    rest = amp == std::string_view::npos ? std::string_view{} : rest.substr(amp + 1);
    const auto equals = option.find('=');
    if (equals == std::string_view::npos) return "option '" + std::string(option) + "' must be key=value";
    const std::string_view key = option.substr(0, equals), value = option.substr(equals + 1);
    if (key == "ttl") {
      if (!whole_number_in(value, 0, 255)) return "ttl must be a whole number from 0 to 255";
    } else if (key == "recv_buf_size") {
      if (!whole_number_in(value, 1, 1L << 30)) return "recv_buf_size must be a positive whole number";
    } else if (key == "transmit_only") {
      if (value != "true" && value != "false") return "transmit_only must be true or false";
    } else {
      return "unknown udpm option '" + std::string(key) + "' (known: ttl, recv_buf_size, transmit_only)";
    }
  }
  return "";
}

std::string problem(const std::string& url) {
  if (url.empty()) return "empty";
  if (url.size() > kMaxUrlLength) return "longer than " + std::to_string(kMaxUrlLength) + " characters";
  for (const unsigned char c : url) {
    if (c <= 0x20 || c >= 0x7f) return "contains a space or a control or non-ASCII character";
  }
  const Parts parts = split(url);
  if (parts.provider.empty()) return "expected provider://network?options, e.g. udpm://239.255.76.67:7667?ttl=0";
  if (parts.provider == "udpm") {
    if (std::string why = udpm_network_problem(parts.network); !why.empty()) return why;
    return udpm_options_problem(parts.options);
  }
  if (parts.provider == "memq") return parts.network.empty() ? "" : "memq:// takes no network";
  if (parts.provider == "file") return parts.network.empty() ? "file:// needs a path" : "";
  if (parts.provider == "tcpq") {
    const auto colon = parts.network.find(':');
    if (colon == std::string::npos || colon == 0 ||
        !whole_number_in(std::string_view(parts.network).substr(colon + 1), 1, 65535)) {
      return "tcpq:// needs host:port";
    }
    return "";
  }
  return "unknown provider '" + parts.provider + "' (known: udpm, memq, file, tcpq)";
}

}  // namespace

void check_lcm_url(const std::string& url, const std::string& option) {
  if (std::string why = problem(url); !why.empty()) {
    // The URL is echoed only when it is printable and short (checked first by problem()).
    const bool printable = url.size() <= kMaxUrlLength &&
                           std::all_of(url.begin(), url.end(), [](unsigned char c) { return c > 0x20 && c < 0x7f; });
    throw InputError(option + (printable ? " '" + url + "'" : std::string()) + ": " + why);
  }
}

}  // namespace bellows
