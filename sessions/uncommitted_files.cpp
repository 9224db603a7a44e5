#include "sessions/uncommitted_files.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <optional>

#include "engine/base/errors.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/session_layout.hpp"

namespace bellows {
namespace {

/// "iteration_0004.r2.csv" with stem "iteration" -> {4, 2}; nullopt for any other name.
struct NumberedName {
  int number = 0;
  int revision = 0;
};
std::optional<NumberedName> parse_numbered(const std::string& name, const std::string& stem, bool revisions) {
  const std::string prefix = stem + "_";
  if (name.size() < prefix.size() + 8 || name.compare(0, prefix.size(), prefix) != 0 ||
      name.compare(name.size() - 4, 4, ".csv") != 0) {
    return std::nullopt;
  }
  const char* at = name.data() + prefix.size();
  const char* end = name.data() + name.size() - 4;
  NumberedName parsed;
  auto [after, error] = std::from_chars(at, end, parsed.number);
  if (error != std::errc() || after - at < 4 || parsed.number < 0) return std::nullopt;
  if (after != end) {
    if (!revisions || end - after < 3 || after[0] != '.' || after[1] != 'r') return std::nullopt;
    const auto [last, revision_error] = std::from_chars(after + 2, end, parsed.revision);
    if (revision_error != std::errc() || last != end || parsed.revision < 1) return std::nullopt;
  }
  return parsed;
}

std::string name_in_folder(const std::string& relative) { return session_layout::folder_and_name(relative).second; }

/// What a hidden temporary was for: ".telemetry.lcmlog.tmp-..." -> "telemetry.lcmlog".
std::string temporary_target(const std::string& name) { return name.substr(1, name.find(".tmp-") - 1); }

bool is_interrupted_log(const std::string& name) {
  return is_temporary_file_name(name) && temporary_target(name).ends_with(".lcmlog");
}

}  // namespace

std::vector<std::string> keep_interrupted_logs(const DirectoryHandle& session) {
  std::vector<std::string> kept;
  for (const std::string& name : entry_names(session)) {
    if (!is_interrupted_log(name)) continue;
    std::string target = temporary_target(name);
    int error = rename_no_replace(session, name, session, target);
    for (int n = 2; error == EEXIST; ++n) {
      target = "telemetry-" + std::to_string(n) + ".lcmlog";  // the names run --lcm-log gives in a session
      error = rename_no_replace(session, name, session, target);
    }
    if (error == 0) kept.push_back(target);  // else removed with the other temporaries, as before
  }
  if (!kept.empty()) sync(session);
  return kept;
}

std::vector<UncommittedFile> find_uncommitted_files(const DirectoryHandle& session, const SessionManifest& manifest) {
  std::vector<UncommittedFile> found;
  for (const std::string& name : entry_names(session)) {
    if (is_temporary_file_name(name) && !is_interrupted_log(name))
      found.push_back({"", name, "an unfinished write of " + temporary_target(name)});
  }
  const auto folder_of = [&](const char* name) -> std::optional<DirectoryHandle> {
    try {
      return session.subdirectory(name);
    } catch (const InputError&) {
      return std::nullopt;  // a link or not a folder: the loader refuses it, nothing here to drop
    }
  };
  const auto listed = static_cast<int>(manifest.iterations.size());
  if (const std::optional<DirectoryHandle> iterations = folder_of(session_layout::kIterations)) {
    for (const std::string& name : entry_names(*iterations)) {
      if (is_temporary_file_name(name)) {
        found.push_back({session_layout::kIterations, name, "an unfinished write"});
      } else if (const auto samples = parse_numbered(name, "iteration", true)) {
        if (name != name_in_folder(session_layout::samples_file(samples->number, samples->revision))) continue;
        if (samples->number >= listed) {
          found.push_back({session_layout::kIterations, name, "iteration " + std::to_string(samples->number)});
        } else if (const int committed =
                       manifest.iterations[static_cast<std::size_t>(samples->number)].samples_revision;
                   samples->revision > committed) {
          found.push_back({session_layout::kIterations, name,
                           "the correction learned from iteration " + std::to_string(samples->number)});
        } else if (samples->revision < committed) {
          found.push_back({session_layout::kIterations, name, ""});  // superseded by the committed revision
        }
      } else if (const auto telemetry = parse_numbered(name, "telemetry", false)) {
        if (name == name_in_folder(session_layout::telemetry_file(telemetry->number)) && telemetry->number >= listed) {
          found.push_back({session_layout::kIterations, name, "iteration " + std::to_string(telemetry->number)});
        }
      }
    }
  }
  if (const std::optional<DirectoryHandle> faults = folder_of(session_layout::kFaults)) {
    const auto boxes = static_cast<int>(manifest.black_boxes.size());
    for (const std::string& name : entry_names(*faults)) {
      if (is_temporary_file_name(name)) {
        found.push_back({session_layout::kFaults, name, "an unfinished write"});
      } else if (const auto box = parse_numbered(name, "blackbox", false)) {
        if (name == name_in_folder(session_layout::black_box_file(box->number)) && box->number >= boxes) {
          found.push_back({session_layout::kFaults, name, "the black box of fault " + std::to_string(box->number + 1)});
        }
      }
    }
  }
  return found;
}

std::string describe_dropped(const std::vector<UncommittedFile>& files) {
  std::vector<std::string> parts;
  for (const UncommittedFile& file : files) {
    // A hidden temporary is the partial copy of a file a crash cut short: named by what it was for.
    const std::string what =
        file.description == "an unfinished write" ? "an unfinished write in " + file.folder + "/" : file.description;
    if (!what.empty() && std::find(parts.begin(), parts.end(), what) == parts.end()) parts.push_back(what);
  }
  std::sort(parts.begin(), parts.end());
  std::string line;
  for (const std::string& part : parts) line += (line.empty() ? "" : "; ") + part;
  return line;
}

void remove_uncommitted_files(const DirectoryHandle& session, const std::vector<UncommittedFile>& files) {
  for (const UncommittedFile& file : files) {
    if (file.folder.empty()) {
      remove_file_at(session, file.name);
    } else if (const std::optional<DirectoryHandle> folder = session.subdirectory(file.folder)) {
      remove_file_at(*folder, file.name);
    }
  }
}

}  // namespace bellows
