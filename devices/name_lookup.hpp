// Looking up a device's host name within a deadline. getaddrinfo has none: a name server that does
// not answer holds it for the resolver's own timeouts (resolv.conf's timeout times attempts, per
// server: tens of seconds), past `[t7] connect_timeout_s` and deaf to Ctrl-C. So a name is looked up
// by glibc's asynchronous getaddrinfo_a, and the caller waits for it in slices that watch the deadline
// and a stop flag. A numeric address is converted at once and asks no name server. A lookup given up
// on may still be running inside glibc: its request stays allocated, reachable, until a later lookup
// finds it done and frees it.
#pragma once

#include <sys/socket.h>

#include <atomic>
#include <string>
#include <vector>

namespace bellows {

/// One address a name resolved to, as socket() and connect() take it.
struct ResolvedAddress {
  int family = 0, socktype = 0, protocol = 0;
  sockaddr_storage address{};
  socklen_t length = 0;
};

struct NameLookupResult {
  std::vector<ResolvedAddress> addresses;  // empty: `error` says why
  std::string error;                       // "cannot resolve HOST: ..."
  bool interrupted = false;                // *stop became true while waiting
};

/// The TCP addresses of `host` (a name or a numeric address) and `service` (a port number), waiting
/// at most until `deadline_s` (std::chrono::steady_clock, in seconds) and no longer than *stop stays
/// false (when `stop` is not null).
NameLookupResult look_up_tcp_addresses(const std::string& host, const std::string& service, double deadline_s,
                                       const std::atomic<bool>* stop);

}  // namespace bellows
