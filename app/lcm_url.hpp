// Checking an LCM bus URL before anything is created: LCM itself reports a bad URL only when the bus
// is opened, with lines of its own on stderr, after a session directory already exists.
#pragma once

#include <string>

namespace bellows {

/// Throws InputError "<option> '<url>': <what is wrong>" unless `url` is one LCM can open:
/// udpm://<multicast IPv4>[:port][?ttl=0..255&recv_buf_size=N], memq://, file://<path>[?options]
/// or tcpq://<host>:<port>.
void check_lcm_url(const std::string& url, const std::string& option);

}  // namespace bellows
