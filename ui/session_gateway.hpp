// How the console saves and opens sessions, without knowing the store's files: app/ gives the
// console an implementation (sessions/ on disk); without one, save and open say they are not
// available. Every call but name_refusal() runs on a worker thread, never on the UI thread, and gets a copy of what
// it needs, so a slow disk never stalls the console or its heartbeat.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/config/configuration.hpp"
#include "engine/base/errors.hpp"
#include "ui/event_log.hpp"
#include "ui/experiment.hpp"

namespace bellows::ui {

/// What a saved session holds, as the console sees it.
struct SessionSnapshot {
  Configuration config;
  Experiment experiment;         // trajectory, trials, next correction, where it is saved
  int first_trial = 0;           // experiment.trials holds iterations first_trial.. (a save needs
                                 // only the unsaved ones and the last saved one, not the history)
  std::vector<LogEntry> events;  // the operator's and the engine's log (the newest entries)
  std::size_t events_total = 0;  // entries ever logged (EventLog::total()), to tell new ones apart
  std::string device_name;       // e.g. "sim"
  std::string rig_profile;       // the rig profile's name it was recorded with ("" without one)
  std::uint64_t seed = 1;
};

/// One saved session as the browser lists it.
struct SessionListing {
  std::string location;  // what open() takes (a directory)
  std::string name;
  std::string date;  // when it started, local time, "2024-05-01 14:03"
  std::string trajectory;
  int iterations = 0;
  double best_rms_deg = -1;  // negative: no iteration
  std::string error;         // not empty: the session cannot be read (the reason)
  std::string device;        // the device it was recorded on (its manifest's "device")
  std::string refusal;       // not empty: this console cannot drive it (the reason; see drive_refusal)
};

/// Why a console driving `console_device` cannot open a session recorded on `listing.device`
/// (it would continue the learning on another rig); empty when it can.
inline std::string drive_refusal(const SessionListing& listing, const std::string& console_device) {
  if (listing.device.empty() || listing.device == console_device) return {};
  return "recorded on the device '" + listing.device + "'; this console drives '" + console_device + "'";
}

class SessionGateway {
 public:
  virtual ~SessionGateway() = default;
  virtual bool available() const = 0;
  /// Why save and open are not available (shown to the operator).
  virtual std::string unavailable_reason() const { return "saving sessions is not available in this build"; }
  /// Saves `snapshot`: a new session, or, when `experiment.session_location` is the session this
  /// gateway opened or saved last, what was added since: trials, black boxes, log entries
  /// (`experiment.saved_events`), changed settings and a changed next correction. The console
  /// calls it as it goes (autosave). Returns the session's location. Throws on failure.
  virtual std::string save(const SessionSnapshot& snapshot) = 0;
  /// Saved sessions, oldest first.
  virtual std::vector<SessionListing> list() = 0;
  /// Loads a session completely. Throws InputError when it cannot be read.
  virtual SessionSnapshot open(const std::string& location) = 0;
  /// Reads a session's configuration, device, trajectory and trials only, to learn from (a transfer):
  /// no lock is taken and the session the console saves into stays what it was. Throws when it
  /// cannot be read; the default says it is not available.
  virtual SessionSnapshot read_trials(const std::string& /*location*/) {
    throw std::runtime_error(unavailable_reason());
  }
  /// Names the session last saved or opened (renames its directory to `name` in the data
  /// directory) and returns its new location. Throws InputError (bad or taken name).
  virtual std::string rename(const std::string& name) { throw InputError("naming sessions is not available: " + name); }
  /// Why rename(name) would refuse `name` for the session at `location` (not a plain directory
  /// name, taken), or "" when it would take it: checked before the console's name prompt closes,
  /// so a refused name keeps it open. Quick (the name's rule and one directory entry) and lock-free:
  /// the one call made on the UI thread.
  virtual std::string name_refusal(const std::string& /*location*/, const std::string& /*name*/) { return {}; }
};

/// The gateway when no session store is built in: everything says "not available".
class UnavailableSessionGateway final : public SessionGateway {
 public:
  explicit UnavailableSessionGateway(std::string reason) : reason_(std::move(reason)) {}
  bool available() const override { return false; }
  std::string unavailable_reason() const override { return reason_; }
  std::string save(const SessionSnapshot&) override { throw std::runtime_error(reason_); }
  std::vector<SessionListing> list() override { return {}; }
  SessionSnapshot open(const std::string&) override { throw std::runtime_error(reason_); }

 private:
  std::string reason_;
};

}  // namespace bellows::ui
