#include "sessions/csv_table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "engine/base/errors.hpp"
#include "engine/base/printable_text.hpp"

namespace bellows {
namespace {

constexpr std::size_t kExcerpt = 80;
std::string excerpt(std::string_view s) { return printable(s, kExcerpt); }

// The widest number append_csv() writes is 24 characters; a hand-edited file may pad fields.
constexpr std::size_t kMostFieldBytes = 40;
constexpr std::string_view kUtf8ByteOrderMark = "\xef\xbb\xbf";

std::string joined(const std::vector<std::string_view>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += ',';
    out += names[i];
  }
  return out;
}

}  // namespace

void append_csv(std::string& out, const std::vector<CsvColumn>& columns) {
  const Eigen::Index rows = columns.empty() ? 0 : columns.front().values->size();
  for (const CsvColumn& column : columns) {
    if (column.values->size() != rows) throw std::invalid_argument("append_csv: columns differ in length");
  }
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (c > 0) out += ',';
    out += columns[c].name;
  }
  out += '\n';
  // Written straight into the string: at most 24 characters per number and its separator.
  constexpr std::size_t kWidest = 25;
  const std::size_t start = out.size();
  out.resize(start + static_cast<std::size_t>(rows) * columns.size() * kWidest);
  char* cursor = out.data() + start;
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      cursor = std::to_chars(cursor, cursor + kWidest, (*columns[c].values)(r)).ptr;
      *cursor++ = c + 1 < columns.size() ? ',' : '\n';
    }
  }
  out.resize(static_cast<std::size_t>(cursor - out.data()));
}

std::size_t csv_size_limit(const std::vector<std::string_view>& header, std::size_t rows) {
  std::size_t header_bytes = kUtf8ByteOrderMark.size() + 2;
  for (std::string_view name : header) header_bytes += name.size() + 1 + kMostFieldBytes;
  return header_bytes + rows * (header.size() * kMostFieldBytes + 2);
}

std::vector<Eigen::VectorXd> parse_csv(std::string_view text, const std::vector<std::string_view>& header,
                                       const std::string& source, NonFinite non_finite) {
  // Spreadsheets on Windows start UTF-8 with a byte order mark and end lines with CR LF: both are
  // accepted (trim() drops the CR).
  if (text.substr(0, kUtf8ByteOrderMark.size()) == kUtf8ByteOrderMark) text.remove_prefix(kUtf8ByteOrderMark.size());
  if (text.empty()) throw InputError(source + ": the file is empty (expected the header '" + joined(header) + "')");
  if (text.back() != '\n') {
    const auto lines = std::count(text.begin(), text.end(), '\n') + 1;
    throw InputError(source + ": truncated: line " + std::to_string(lines) + " has no end of line");
  }
  const std::size_t header_end = text.find('\n');
  const std::string_view header_line = trim(text.substr(0, header_end));
  if (header_line != joined(header)) {
    throw InputError(source + ": line 1: the header must be '" + joined(header) + "', found '" + excerpt(header_line) +
                     "'");
  }
  std::string_view body = text.substr(header_end + 1);
  const auto rows = static_cast<Eigen::Index>(std::count(body.begin(), body.end(), '\n'));
  std::vector<Eigen::VectorXd> columns(header.size(), Eigen::VectorXd(rows));
  for (Eigen::Index r = 0; r < rows; ++r) {
    const std::size_t line_end = body.find('\n');
    const std::string_view line = body.substr(0, line_end);
    body.remove_prefix(line_end + 1);
    const auto where = [&] { return source + ": line " + std::to_string(r + 2); };
    if (trim(line).empty()) throw InputError(where() + ": empty line");
    std::string_view rest = line;
    for (std::size_t c = 0; c < header.size(); ++c) {
      const std::size_t comma = rest.find(',');
      const bool last = c + 1 == header.size();
      if (last != (comma == std::string_view::npos)) {
        throw InputError(where() + ": expected " + std::to_string(header.size()) + " fields ('" + joined(header) +
                         "'), found '" + excerpt(line) + "'");
      }
      const std::string_view field = trim(rest.substr(0, comma));
      rest.remove_prefix(last ? rest.size() : comma + 1);
      double value = 0.0;
      const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
      if (field.empty() || error != std::errc() || end != field.data() + field.size()) {
        throw InputError(where() + ", column " + std::string(header[c]) + ": '" + excerpt(field) + "' is not a number");
      }
      if (!std::isfinite(value) && non_finite == NonFinite::kRefuse) {
        throw InputError(where() + ", column " + std::string(header[c]) + ": '" + excerpt(field) +
                         "' is not a finite number");
      }
      columns[c](r) = value;
    }
  }
  return columns;
}

}  // namespace bellows
