// Strict, typed reading of JSON with the path of every value, so that a bad manifest gets an error
// that says where and what: "session S: manifest.json: /iterations/3/rms_deg: expected a number".
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace bellows {

/// Parses JSON text; throws InputError starting with `source` when it is not JSON.
nlohmann::ordered_json parse_json(std::string_view text, const std::string& source);

class JsonReader {
 public:
  /// `value` must outlive the reader; `source` (e.g. "session S: manifest.json") is copied.
  JsonReader(const nlohmann::ordered_json& value, const std::string& source, std::string path = "")
      : value_(&value), source_(std::make_shared<const std::string>(source)), path_(std::move(path)) {}

  /// A required member of an object.
  JsonReader operator[](std::string_view key) const;
  bool has(std::string_view key) const;
  /// An element of an array.
  JsonReader operator[](std::size_t index) const;
  /// Size of an array (throws unless this is an array).
  std::size_t size() const;

  double number() const;  // finite
  int integer(int lowest, int highest) const;
  std::uint64_t hex_word() const;  // a "0x..." string of up to 16 hex digits
  bool boolean() const;
  std::string text() const;

  void expect_object() const;
  const nlohmann::ordered_json& json() const { return *value_; }
  [[noreturn]] void fail(const std::string& message) const;

 private:
  JsonReader(const nlohmann::ordered_json& value, std::shared_ptr<const std::string> source, std::string path)
      : value_(&value), source_(std::move(source)), path_(std::move(path)) {}

  const nlohmann::ordered_json* value_;
  std::shared_ptr<const std::string> source_;
  std::string path_;
};

/// A 64-bit word as "0x" and 16 hex digits: exact in every JSON reader, unlike a large number.
std::string hex_word(std::uint64_t word);

}  // namespace bellows
