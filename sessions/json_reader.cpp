#include "sessions/json_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "engine/base/errors.hpp"

namespace bellows {

namespace {

// A manifest nests a few levels; a hostile one nested 100 000 deep parses, but copying it recurses
// once a level (nlohmann) and overflows the stack of whoever reads it: show, list, the console.
constexpr int kMaxJsonDepth = 64;

/// The deepest nesting of arrays and objects in `text` (strings skipped).
int json_depth(std::string_view text) {
  int depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > kMaxJsonDepth) return deepest;  // no need to read on
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

}  // namespace

nlohmann::ordered_json parse_json(std::string_view text, const std::string& source) {
  if (json_depth(text) > kMaxJsonDepth) {
    throw InputError(source + ": not valid here: arrays and objects nested more than " + std::to_string(kMaxJsonDepth) +
                     " levels deep");
  }
  try {
    return nlohmann::ordered_json::parse(text);
  } catch (const nlohmann::json::exception& error) {
    throw InputError(source + ": not valid JSON: " + error.what());
  }
}

void JsonReader::fail(const std::string& message) const {
  throw InputError(*source_ + ": " + (path_.empty() ? "/" : path_) + ": " + message);
}

void JsonReader::expect_object() const {
  if (!value_->is_object()) fail("expected an object");
}

bool JsonReader::has(std::string_view key) const {
  expect_object();
  return value_->find(key) != value_->end();
}

JsonReader JsonReader::operator[](std::string_view key) const {
  expect_object();
  const auto found = value_->find(key);
  if (found == value_->end()) fail("missing \"" + std::string(key) + "\"");
  return JsonReader(*found, source_, path_ + "/" + std::string(key));
}

JsonReader JsonReader::operator[](std::size_t index) const {
  if (!value_->is_array()) fail("expected an array");
  if (index >= value_->size()) fail("expected at least " + std::to_string(index + 1) + " elements");
  return JsonReader((*value_)[index], source_, path_ + "/" + std::to_string(index));
}

std::size_t JsonReader::size() const {
  if (!value_->is_array()) fail("expected an array");
  return value_->size();
}

double JsonReader::number() const {
  if (!value_->is_number())
    fail(value_->is_null() ? "expected a number, found null (not a number?)" : "expected a number");
  const double value = value_->get<double>();
  if (!std::isfinite(value)) fail("expected a finite number");
  return value;
}

int JsonReader::integer(int lowest, int highest) const {
  if (!value_->is_number_integer()) fail("expected a whole number");
  // Unsigned values beyond int64 would wrap in get<int64_t>(); compare them as unsigned first.
  const bool too_large = value_->is_number_unsigned() &&
                         (highest < 0 || value_->get<std::uint64_t>() > static_cast<std::uint64_t>(highest));
  const bool in_range = !too_large && value_->get<std::int64_t>() >= lowest && value_->get<std::int64_t>() <= highest;
  if (!in_range) {
    fail("expected a whole number in [" + std::to_string(lowest) + ", " + std::to_string(highest) + "], found " +
         value_->dump());
  }
  return static_cast<int>(value_->get<std::int64_t>());
}

std::uint64_t JsonReader::hex_word() const {
  const std::string s = text();
  std::uint64_t word = 0;
  const char* begin = s.data() + 2;
  const char* end = s.data() + s.size();
  if (s.size() < 3 || s.size() > 18 || s[0] != '0' || (s[1] != 'x' && s[1] != 'X'))
    fail("expected \"0x\" and hex digits");
  const auto [stop, error] = std::from_chars(begin, end, word, 16);
  if (error != std::errc() || stop != end) fail("expected \"0x\" and hex digits");
  return word;
}

bool JsonReader::boolean() const {
  if (!value_->is_boolean()) fail("expected true or false");
  return value_->get<bool>();
}

std::string JsonReader::text() const {
  if (!value_->is_string()) fail("expected a string");
  return value_->get<std::string>();
}

std::string hex_word(std::uint64_t word) {
  char buffer[19] = "0x";
  const auto result = std::to_chars(buffer + 2, buffer + sizeof buffer, word, 16);
  const std::size_t digits = static_cast<std::size_t>(result.ptr - (buffer + 2));
  return "0x" + std::string(16 - digits, '0') + std::string(buffer + 2, result.ptr);
}

}  // namespace bellows
