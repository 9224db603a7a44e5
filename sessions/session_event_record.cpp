#include "sessions/session_event_record.hpp"

namespace bellows {
namespace {

constexpr int kMostIterations = 1000000;
// An engine time beyond this is no engine's (a run of a year): a damaged or hostile manifest.
constexpr double kMostEngineTimeS = 366.0 * 24 * 3600;

bool always(const SessionEvent&) { return true; }

}  // namespace

const std::vector<EventField>& event_record_fields() {
  using Json = nlohmann::ordered_json;
  static const std::vector<EventField> fields = {
      {"time_utc", "when it happened, ISO 8601 UTC", true, always,
       [](const SessionEvent& e) { return Json(e.time_utc); },
       [](SessionEvent& e, const JsonReader& r) { e.time_utc = r.text(); }, false},
      {"iteration", "the iteration running or next to run", false, always,
       [](const SessionEvent& e) { return Json(e.iteration); },
       [](SessionEvent& e, const JsonReader& r) { e.iteration = r.integer(0, kMostIterations); }, false},
      {"kind", "start, resume, finish, fault, operator, engine, console-log, ...", true, always,
       [](const SessionEvent& e) { return Json(e.kind); },
       [](SessionEvent& e, const JsonReader& r) { e.kind = r.text(); }, false},
      {"message", "what happened, for people", true, always, [](const SessionEvent& e) { return Json(e.message); },
       [](SessionEvent& e, const JsonReader& r) { e.message = r.text(); }, false},
      {"engine_time_s", "the engine's time when it happened, in seconds (absent: not known)", false,
       [](const SessionEvent& e) { return e.engine_time_s >= 0.0; },
       [](const SessionEvent& e) { return Json(e.engine_time_s); },
       [](SessionEvent& e, const JsonReader& r) {
         const double t = r.number();
         if (t < 0.0 || t > kMostEngineTimeS) r.fail("expected an engine time from 0 to a year, in seconds");
         e.engine_time_s = t;
       },
       true},
  };
  return fields;
}

nlohmann::ordered_json event_to_json(const SessionEvent& event) {
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  for (const EventField& f : event_record_fields()) {
    if (f.known(event)) out[std::string(f.name)] = f.value(event);
  }
  return out;
}

SessionEvent event_from_json(const JsonReader& reader) {
  SessionEvent event;
  for (const EventField& f : event_record_fields()) {
    if (!f.optional || reader.has(f.name)) f.read(event, reader[f.name]);
  }
  return event;
}

}  // namespace bellows
