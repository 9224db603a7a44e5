#include "devices/name_lookup.hpp"

#include <netdb.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>

namespace bellows {
namespace {

// How often a wait looks at the stop flag (as ModbusClient's waits do).
constexpr double kLookupStopSlice_s = 0.02;

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// One getaddrinfo_a request and what it points to: glibc reads and writes these until it is done.
struct PendingLookup {
  std::string host, service;
  addrinfo hints{};
  gaicb request{};
};

// Lookups given up on while glibc still ran them. A leaked pointer, not a static vector: at exit a
// destructor would free requests glibc's thread may still be writing.
std::mutex& abandoned_mutex() {
  static std::mutex mutex;
  return mutex;
}
std::vector<std::unique_ptr<PendingLookup>>& abandoned() {
  static auto* list = new std::vector<std::unique_ptr<PendingLookup>>;
  return *list;
}

void release(PendingLookup& lookup) {
  if (lookup.request.ar_result != nullptr) freeaddrinfo(lookup.request.ar_result);
  lookup.request.ar_result = nullptr;
}

void give_up(std::unique_ptr<PendingLookup> lookup) {
  const std::lock_guard<std::mutex> guard(abandoned_mutex());
  auto& list = abandoned();
  // Those glibc has finished since: theirs to free now.
  list.erase(std::remove_if(list.begin(), list.end(),
                            [](const std::unique_ptr<PendingLookup>& done) {
                              if (gai_error(&done->request) == EAI_INPROGRESS) return false;
                              release(*done);
                              return true;
                            }),
             list.end());
  if (gai_cancel(&lookup->request) == EAI_NOTCANCELED) {
    list.push_back(std::move(lookup));
    return;
  }
  release(*lookup);  // cancelled, or done meanwhile
}

std::vector<ResolvedAddress> addresses_of(const addrinfo* found) {
  std::vector<ResolvedAddress> addresses;
  for (const addrinfo* a = found; a != nullptr; a = a->ai_next) {
    if (a->ai_addrlen > sizeof(sockaddr_storage)) continue;
    ResolvedAddress r{a->ai_family, a->ai_socktype, a->ai_protocol, {}, a->ai_addrlen};
    std::memcpy(&r.address, a->ai_addr, a->ai_addrlen);
    addresses.push_back(r);
  }
  return addresses;
}

NameLookupResult result_of(const std::string& host, int status, const addrinfo* found) {
  NameLookupResult result;
  if (status != 0) {
    result.error = "cannot resolve " + host + ": " + gai_strerror(status);
    return result;
  }
  result.addresses = addresses_of(found);
  if (result.addresses.empty()) result.error = "cannot resolve " + host + ": no address";
  return result;
}

}  // namespace

NameLookupResult look_up_tcp_addresses(const std::string& host, const std::string& service, double deadline_s,
                                       const std::atomic<bool>* stop) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  // A numeric address: converted here, no name server asked (and no thread of glibc's started).
  hints.ai_flags = AI_NUMERICHOST | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  if (getaddrinfo(host.c_str(), service.c_str(), &hints, &found) == 0) {
    NameLookupResult result = result_of(host, 0, found);
    freeaddrinfo(found);
    return result;
  }

  auto lookup = std::make_unique<PendingLookup>();
  lookup->host = host;
  lookup->service = service;
  lookup->hints = hints;
  lookup->hints.ai_flags = AI_NUMERICSERV;  // the name, asked of the name service
  lookup->request.ar_name = lookup->host.c_str();
  lookup->request.ar_service = lookup->service.c_str();
  lookup->request.ar_request = &lookup->hints;
  gaicb* requests[] = {&lookup->request};
  if (const int error = getaddrinfo_a(GAI_NOWAIT, requests, 1, nullptr); error != 0) {
    return result_of(host, error, nullptr);
  }
  int status = EAI_INPROGRESS;
  bool interrupted = false;
  while ((status = gai_error(&lookup->request)) == EAI_INPROGRESS) {
    if (stop != nullptr && stop->load(std::memory_order_relaxed)) {
      interrupted = true;
      break;
    }
    const double left_s = deadline_s - steady_seconds();
    if (left_s <= 0.0) break;
    const double slice_s = stop != nullptr ? std::min(left_s, kLookupStopSlice_s) : left_s;
    const timespec wait{static_cast<time_t>(slice_s), static_cast<long>(std::fmod(slice_s, 1.0) * 1e9)};
    gai_suspend(requests, 1, &wait);  // returns when done, after the slice, or on a signal
  }
  if (status == EAI_INPROGRESS) {
    give_up(std::move(lookup));
    NameLookupResult result;
    result.interrupted = interrupted;
    result.error = interrupted ? "interrupted" : "cannot resolve " + host + ": the name service did not answer in time";
    return result;
  }
  NameLookupResult result = result_of(host, status, lookup->request.ar_result);
  release(*lookup);
  return result;
}

}  // namespace bellows
