// The console's save and open on the session store (sessions/). The console saves as it goes: the
// first save creates a session in the data directory; later saves append the new iterations, black
// boxes and log entries, and rewrite the last iteration's next correction when learning changed it. Each saved
// iteration's "next correction" is what the following trial ran with; for the last one saved, the
// correction the console had chosen for the next trial at the time of saving (learning after the
// save shows in the next trial's own samples, u_ilc). Opening a
// session takes its lock, like `bellows run --resume`, so that the console continues it; the lock
// is held until another session is opened or created, or the console exits. Every call may come
// from a console background task: one at a time (a mutex).
#pragma once

#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include "sessions/session_writer.hpp"
#include "ui/session_gateway.hpp"

namespace bellows {

class StoreSessionGateway final : public ui::SessionGateway {
 public:
  /// `device_name`: the console's device; a session recorded on another one is not opened.
  /// `device_info`: what a new session records about it (seed, bus, address, rig profile).
  /// `data_dir`: where sessions live (--data-dir); empty: the default (XDG_DATA_HOME, HOME).
  /// `model_source`: where a new session's [model] came from (app/learning_model).
  explicit StoreSessionGateway(std::string device_name,
                               nlohmann::ordered_json device_info = nlohmann::ordered_json::object(),
                               const std::string& data_dir = {}, std::string model_source = "configuration");

  bool available() const override { return !data_dir_.empty(); }
  std::string unavailable_reason() const override { return reason_; }
  std::string save(const ui::SessionSnapshot& snapshot) override;
  std::vector<ui::SessionListing> list() override;
  ui::SessionSnapshot open(const std::string& location) override;
  ui::SessionSnapshot read_trials(const std::string& location) override;
  std::string rename(const std::string& name) override;
  std::string name_refusal(const std::string& location, const std::string& name) override;

  const std::filesystem::path& data_dir() const { return data_dir_; }
  /// Runs `read` while no save, rename or open runs (each rewrites files a reader could see half
  /// changed): the console's figures read the session it saves into (app/plot_console.hpp).
  void read_quietly(const std::function<void()>& read);

 private:
  std::mutex mutex_;
  std::string device_name_;
  nlohmann::ordered_json device_info_;
  std::string model_source_;
  std::filesystem::path data_dir_;  // empty: not available (reason_ says why)
  std::string reason_;
  std::optional<SessionWriter> writer_;  // the session the console saves into
  /// After a new session's first save failed past its creation: the log entries its header holds.
  static constexpr std::size_t kConfirmed = static_cast<std::size_t>(-1);
  std::size_t unconfirmed_events_ = kConfirmed;
};

/// "2024-05-01T14:03:07.123Z" as local time "2024-05-01 14:03" (the text itself if it does not parse).
std::string local_date_of(const std::string& utc);

}  // namespace bellows
