// Numeric CSV as sessions store it: one header line of column names, then one line per row of
// comma-separated numbers in the shortest form that reads back to the same double. Plain enough for
// spreadsheets, pandas, MATLAB readtable and PlotJuggler; strict on reading: the exact header, the
// same field count on every line, finite numbers only, a final end of line (else: truncated).
// Text from the file that an error quotes is escaped and shortened (engine/base/printable_text.hpp).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

namespace bellows {

struct CsvColumn {
  std::string_view name;
  const Eigen::VectorXd* values;
};

/// Appends header and rows to `out`. Throws std::invalid_argument if the columns differ in length.
void append_csv(std::string& out, const std::vector<CsvColumn>& columns);

/// Whether `nan` and `inf` are values (a black box keeps the bad reading that caused its fault).
enum class NonFinite { kRefuse, kAccept };

/// The most bytes a file of `rows` rows under `header` can take (numbers padded with spaces, CR LF
/// line ends and a byte order mark included): a bigger file is refused before it is read.
std::size_t csv_size_limit(const std::vector<std::string_view>& header, std::size_t rows);

/// Parses `text` whose header must be exactly `header` (a UTF-8 byte order mark and CR LF line
/// ends are accepted); one vector per column. Throws InputError
/// that starts with `source` and names the line (and column) at fault.
std::vector<Eigen::VectorXd> parse_csv(std::string_view text, const std::vector<std::string_view>& header,
                                       const std::string& source, NonFinite non_finite = NonFinite::kRefuse);

}  // namespace bellows
