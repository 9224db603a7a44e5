// The session's file formats on their own: numeric CSV, the iteration and trajectory files, exact
// degrees, strict JSON reading, atomic writes.
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <gtest/gtest.h>

#include "engine/base/errors.hpp"
#include "session_test_support.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/csv_table.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/json_reader.hpp"
#include "tests/test_support.hpp"
#include "engine/base/units.hpp"

namespace bellows {
namespace {

using testing::TempDir;

using testing::error_of;

TEST(CsvTable, RoundTripsEveryDoubleExactly) {
  Eigen::VectorXd a(6), b(6);
  a << 0.0, -0.0, 1e-300, 0.1 + 0.2, std::numeric_limits<double>::max(), -123456.789;
  b << std::numeric_limits<double>::denorm_min(), 1.0 / 3.0, 2.5, -1e22, 42.0, std::nextafter(1.0, 2.0);
  std::string text;
  append_csv(text, {{"a", &a}, {"b_bar", &b}});
  EXPECT_EQ(text.substr(0, text.find('\n')), "a,b_bar");
  const auto columns = parse_csv(text, {"a", "b_bar"}, "t.csv");
  ASSERT_EQ(columns.size(), 2u);
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    EXPECT_EQ(columns[0](i), a(i));
    EXPECT_EQ(std::signbit(columns[0](i)), std::signbit(a(i)));
    EXPECT_EQ(columns[1](i), b(i));
  }
}

TEST(CsvTable, WritesShortNumbers) {
  Eigen::VectorXd a(3);
  a << 0.5, 30.0, 1.01325;
  std::string text;
  append_csv(text, {{"x", &a}});
  EXPECT_EQ(text, "x\n0.5\n30\n1.01325\n");
}

TEST(CsvTable, RejectsMalformedTextWithTheLineAtFault) {
  const std::vector<std::string_view> header = {"a", "b"};
  const auto parse = [&](const std::string& text) { return error_of([&] { parse_csv(text, header, "f.csv"); }); };
  EXPECT_NE(parse("").find("f.csv: the file is empty"), std::string::npos);
  EXPECT_NE(parse("a,b\n1,2\n3,").find("f.csv: truncated: line 3 has no end of line"), std::string::npos);
  EXPECT_NE(parse("a,c\n1,2\n").find("line 1: the header must be 'a,b', found 'a,c'"), std::string::npos);
  EXPECT_NE(parse("a,b\n1,2,3\n").find("line 2: expected 2 fields"), std::string::npos);
  EXPECT_NE(parse("a,b\n1\n").find("line 2: expected 2 fields"), std::string::npos);
  EXPECT_NE(parse("a,b\n1,2\n\n").find("line 3: empty line"), std::string::npos);
  EXPECT_NE(parse("a,b\n1,x\n").find("line 2, column b: 'x' is not a number"), std::string::npos);
  EXPECT_NE(parse("a,b\nnan,1\n").find("line 2, column a: 'nan' is not a finite number"), std::string::npos);
  EXPECT_NE(parse("a,b\n1,inf\n").find("not a finite number"), std::string::npos);
  EXPECT_NE(parse("a,b\n1,1e999\n").find("is not a number"), std::string::npos);
  EXPECT_NE(parse("a,b\n1,2 3\n").find("is not a number"), std::string::npos);
  EXPECT_NE(parse("a,b\n1,\n").find("'' is not a number"), std::string::npos);
}

TEST(CsvTable, AcceptsWindowsLineEndsAndSpaces) {
  const auto columns = parse_csv("a,b\r\n 1 , 2\r\n", {"a", "b"}, "f.csv");
  EXPECT_EQ(columns[0](0), 1.0);
  EXPECT_EQ(columns[1](0), 2.0);
}

TEST(ExactDegrees, ReadBackToTheSameRadiansAndPreferShortDecimals) {
  EXPECT_EQ(degrees_for_exact_radians(30.0 * kRadPerDeg), 30.0);
  EXPECT_EQ(degrees_for_exact_radians(-28.4 * kRadPerDeg), -28.4);
  int exact = 0, total = 0;
  for (double deg = -95.0; deg <= 95.0; deg += 0.0137) {
    const double rad = deg * kRadPerDeg;
    ++total;
    exact += radians_from_degrees(degrees_for_exact_radians(rad)) == rad;
  }
  EXPECT_EQ(exact, total);                                // every angle that came from degrees reads back bit for bit
  for (double rad = -1.6; rad <= 1.6; rad += 0.000731) {  // arbitrary radians: within an ulp
    EXPECT_NEAR(radians_from_degrees(degrees_for_exact_radians(rad)), rad, 2e-16 * std::abs(rad) + 1e-300);
  }
}

TEST(IterationFiles, TrajectoryRoundTripsExactly) {
  const Trajectory trajectory = testing::short_trajectory(0.02);
  const std::string text = format_trajectory_csv(trajectory);
  EXPECT_EQ(text.substr(0, 17), "time_s,angle_deg\n");
  const Trajectory loaded = parse_trajectory_csv_file(text, "t.csv", trajectory.name, trajectory.learning_samples(),
                                                      0.02, TrajectoryLimits{});
  EXPECT_EQ(loaded.name, trajectory.name);
  EXPECT_EQ(loaded.sample_time_s, trajectory.sample_time_s);
  ASSERT_EQ(loaded.joint(0).size(), trajectory.joint(0).size());
  for (Eigen::Index k = 0; k < loaded.joint(0).size(); ++k) EXPECT_EQ(loaded.joint(0)(k), trajectory.joint(0)(k));
}

TEST(IterationFiles, TrajectoryChecksLengthSamplingAndLimits) {
  const Trajectory trajectory = testing::short_trajectory(0.02);
  const std::string text = format_trajectory_csv(trajectory);
  EXPECT_NE(error_of([&] { parse_trajectory_csv_file(text, "t.csv", "x", 30, 0.02, {}); }).find("expected 31 rows"),
            std::string::npos);
  EXPECT_NE(error_of([&] { parse_trajectory_csv_file(text, "t.csv", "x", 25, 0.01, {}); }).find("not uniform"),
            std::string::npos);
  TrajectoryLimits narrow;
  narrow.max_abs_angle_deg = 10.0;
  EXPECT_NE(error_of([&] { parse_trajectory_csv_file(text, "t.csv", "x", 25, 0.02, narrow); }).find("joint range"),
            std::string::npos);
}

// The fuzzer's find (fuzz_session_readers, 2026-12-01): telemetry read into a record that had no
// joints yet built an empty header and read its first column out of bounds.
TEST(IterationFiles, TelemetryRefusesAnEmptyFileAndARecordWithoutJoints) {
  IterationData data;
  EXPECT_THROW(parse_telemetry_csv("\r\n", "t.csv", 25, 4, 0.005, data), std::logic_error);
  data.record.prepare(25, 4);
  EXPECT_NE(error_of([&] { parse_telemetry_csv("\r\n", "t.csv", 25, 4, 0.005, data); }).find("t.csv"),
            std::string::npos);
}

TEST(JsonReader, NamesThePathOfEveryFault) {
  const auto json = parse_json(R"({"a": {"b": [1, "x", null]}, "n": 5, "h": "0x00000000000000ff"})", "m.json");
  const JsonReader r(json, "m.json");
  EXPECT_EQ(r["a"]["b"][0].number(), 1.0);
  EXPECT_EQ(error_of([&] { r["a"]["b"][1].number(); }), "m.json: /a/b/1: expected a number");
  EXPECT_EQ(error_of([&] { r["a"]["b"][2].number(); }),
            "m.json: /a/b/2: expected a number, found null (not a number?)");
  EXPECT_EQ(error_of([&] { r["a"]["c"]; }), "m.json: /a: missing \"c\"");
  EXPECT_EQ(error_of([&] { r["a"]["b"][9]; }), "m.json: /a/b: expected at least 10 elements");
  EXPECT_EQ(error_of([&] { r["n"].integer(0, 3); }), "m.json: /n: expected a whole number in [0, 3], found 5");
  EXPECT_EQ(r["h"].hex_word(), 255u);
  EXPECT_EQ(hex_word(255), "0x00000000000000ff");
  EXPECT_NE(error_of([] { parse_json("{\"a\": ", "m.json"); }).find("m.json: not valid JSON"), std::string::npos);
}

TEST(JsonReader, RejectsIntegersOutsideTheRangeWithoutWrapping) {
  const auto json = parse_json(R"({"big": 18446744073709551615, "neg": -3, "real": 1.5})", "m.json");
  const JsonReader r(json, "m.json");
  EXPECT_NE(error_of([&] { r["big"].integer(-10, 10); }).find("expected a whole number in [-10, 10]"),
            std::string::npos);
  EXPECT_EQ(r["neg"].integer(-10, 10), -3);
  EXPECT_NE(error_of([&] { r["neg"].integer(0, 10); }).find("in [0, 10]"), std::string::npos);
  EXPECT_EQ(error_of([&] { r["real"].integer(0, 10); }), "m.json: /real: expected a whole number");
}

TEST(AtomicFile, ReplacesContentsAndLeavesNoTemporaryFile) {
  TempDir dir;
  const auto path = dir / "f.txt";
  write_file_atomic(path, "first");
  write_file_atomic(path, "second");
  EXPECT_EQ(read_file(path), "second");
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1);
  EXPECT_TRUE(is_temporary_file_name(unpredictable_temporary_name("f.txt")));
  EXPECT_NE(unpredictable_temporary_name("f.txt"), unpredictable_temporary_name("f.txt"));  // not guessable
  EXPECT_FALSE(is_temporary_file_name("f.txt"));
}

TEST(AtomicFile, RemovesLeftoversOfACrashedWriter) {
  TempDir dir;
  testing::write_text(dir / ".manifest.json.tmp-99999", "partial");
  testing::write_text(dir / "keep.csv", "x\n");
  remove_temporary_files(DirectoryHandle::open(dir.path()));
  EXPECT_FALSE(std::filesystem::exists(dir / ".manifest.json.tmp-99999"));
  EXPECT_TRUE(std::filesystem::exists(dir / "keep.csv"));
}

TEST(AtomicFile, ReportsWhyItCannotWrite) {
  EXPECT_NE(error_of([] { write_file_atomic("/nonexistent-dir/f.txt", "x"); }).find("cannot create"),
            std::string::npos);
  EXPECT_NE(error_of([] { read_file("/nonexistent-dir/f.txt"); }).find("No such file"), std::string::npos);
}

/// A disk that cannot be written is the environment's refusal (exit status 4); a name that is
/// wrong is bad input (2, nothing changed): docs/architecture.md, "Exit statuses".
TEST(FileErrors, AFullOrBrokenDiskIsTheEnvironmentAWrongNameIsTheInput) {
  for (const int environment : {ENOSPC, EDQUOT, EROFS, EIO, EMFILE}) {
    SCOPED_TRACE(std::strerror(environment));
    EXPECT_TRUE(is_environment_failure(environment));
    try {
      throw_file_error("cannot write x.csv", environment);
    } catch (const EnvironmentError& error) {
      EXPECT_EQ(error.exit_status(), kExitEnvironment);
      EXPECT_EQ(std::string(error.what()), std::string("cannot write x.csv: ") + std::strerror(environment));
    }
  }
  for (const int input : {ENOENT, ENOTDIR, EISDIR, ELOOP, EACCES, EEXIST}) {
    SCOPED_TRACE(std::strerror(input));
    EXPECT_FALSE(is_environment_failure(input));
    EXPECT_THROW(throw_file_error("cannot write x.csv", input), InputError);
  }
  // Through the safe writer: a missing folder is the operator's input.
  try {
    write_file_atomic("/nonexistent-dir/f.txt", "x");
    ADD_FAILURE() << "wrote into a missing folder";
  } catch (const InputError&) {
  }
}

}  // namespace
}  // namespace bellows
