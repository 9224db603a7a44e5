// Setting a few keys of one table in a TOML file's text by hand, line by line, so that everything
// else in the file (comments, order, other tables) stays as the operator wrote it. toml++ can
// rewrite a document but drops its comments; a rig profile or a lab configuration is annotated.
// Callers re-parse the result with their own loader before writing it anywhere.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace bellows {

/// `text` with each (key, value) of `values` set in table `table` ("" = the top level, before the
/// first table header): an existing `key = ...` line is replaced, a missing key is added right
/// after the table's header (the top level: before the first header), a missing table is appended.
/// `value` is TOML text as written (a number: "0.25"). Each line it writes ends with `# comment`.
std::string with_table_values(const std::string& text, const std::string& table,
                              const std::vector<std::pair<std::string, std::string>>& values,
                              const std::string& comment);

/// Whether `text` has the header line of table `table` ("[valves]", a comment after it allowed).
bool has_table_header(const std::string& text, const std::string& table);

/// A number as the files bellows writes hold it: "%.9g" (round-trips what a sensor can resolve).
std::string toml_number(double value);

}  // namespace bellows
