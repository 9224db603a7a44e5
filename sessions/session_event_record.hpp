// A session's event record (the manifest's `events`), described once: its fields in file order,
// what each means, and how it is written and read. The manifest, `sessions show --json` and the MAT
// export take the event's fields from here (docs/session-format.md lists the same).
#pragma once

#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "sessions/json_reader.hpp"
#include "sessions/session.hpp"

namespace bellows {

struct EventField {
  std::string_view name;     // the JSON key (and the MAT export's field)
  std::string_view meaning;  // one line for people
  bool text;                 // a string (else a number)
  /// False for an optional field the event does not hold: it is not written (sessions saved
  /// before the field existed, and events whose value was never known, read back the same).
  bool (*known)(const SessionEvent& event);
  nlohmann::ordered_json (*value)(const SessionEvent& event);
  void (*read)(SessionEvent& event, const JsonReader& reader);  // called only when the key is there
  bool optional;
};

/// The event's fields in file order.
const std::vector<EventField>& event_record_fields();

nlohmann::ordered_json event_to_json(const SessionEvent& event);
SessionEvent event_from_json(const JsonReader& reader);

}  // namespace bellows
