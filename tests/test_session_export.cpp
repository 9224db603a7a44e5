// Exports: MAT v5 by default and v7.3 on request (read back with libmatio here, and by scipy and
// Octave in test_session_readers), the black box in both formats with names for its codes, and
// the refusals: an existing file (any of the CSV siblings), the session's own folder, a wrong
// extension, a missing folder.
#include <gtest/gtest.h>
#include <matio.h>

#include <cmath>

#include "engine/base/errors.hpp"
#include "sessions/black_box_file.hpp"
#include "sessions/record_columns.hpp"
#include "sessions/csv_table.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/session_export.hpp"
#include "sessions/session_layout.hpp"
#include "tests/session_export_fixture.hpp"

namespace bellows {
namespace {

namespace fs = std::filesystem;
using testing::ProcessResult;
using testing::run_bellows;
using testing::TempDir;

class SessionExport : public ::testing::Test {
 protected:
  void SetUp() override { session_ = testing::saved_faulted_session(dir_ / "s"); }
  std::string message_of(const std::function<void()>& work) {
    try {
      work();
    } catch (const InputError& error) {
      return error.what();
    }
    return "";
  }
  TempDir dir_;
  Session session_;
};

std::vector<double> doubles(matvar_t* var) {
  if (var == nullptr || var->class_type != MAT_C_DOUBLE) return {};
  const double* data = static_cast<const double*>(var->data);
  return std::vector<double>(data, data + var->dims[0] * var->dims[1]);
}

/// ASCII text of a char variable (MAT v5 reads back as UTF-16 code units, v7.3 as bytes).
std::string chars(matvar_t* var) {
  if (var == nullptr || var->class_type != MAT_C_CHAR) return "<not text>";
  std::string out;
  const std::size_t count = var->dims[0] * var->dims[1];
  for (std::size_t i = 0; i < count; ++i) {
    out += var->data_size == 2 ? static_cast<char>(static_cast<const std::uint16_t*>(var->data)[i])
                               : static_cast<const char*>(var->data)[i];
  }
  return out;
}

void expect_mat_contents(const fs::path& path, const Session& session, mat_ft version) {
  mat_t* file = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
  ASSERT_NE(file, nullptr);
  EXPECT_EQ(Mat_GetVersion(file), version);
  matvar_t* iterations = Mat_VarRead(file, "iterations");
  ASSERT_NE(iterations, nullptr);
  ASSERT_EQ(iterations->dims[0] * iterations->dims[1], session.iterations.size());
  for (std::size_t i = 0; i < session.iterations.size(); ++i) {
    EXPECT_EQ(doubles(Mat_VarGetStructFieldByName(iterations, "rms_deg", i)),
              std::vector<double>{session.manifest.iterations[i].summary.rms_deg});
    matvar_t* samples = Mat_VarGetStructFieldByName(iterations, "samples", i);
    const std::vector<double> u_ilc = doubles(Mat_VarGetStructFieldByName(samples, "u_ilc_bar", 0));
    const Eigen::VectorXd& saved = session.iterations[i].record.joint_samples(0).u_ilc_bar;
    EXPECT_EQ(u_ilc, std::vector<double>(saved.data(), saved.data() + saved.size()));
  }
  Mat_VarFree(iterations);
  matvar_t* boxes = Mat_VarRead(file, "black_boxes");
  ASSERT_NE(boxes, nullptr);
  ASSERT_EQ(boxes->dims[0] * boxes->dims[1], 1u);
  EXPECT_EQ(chars(Mat_VarGetStructFieldByName(boxes, "fault", 0)), "sensor-nan");
  matvar_t* ticks = Mat_VarGetStructFieldByName(boxes, "ticks", 0);
  ASSERT_NE(ticks, nullptr);
  const std::vector<TickRecord>& box = session.black_boxes[0];
  const std::vector<double> angle = doubles(Mat_VarGetStructFieldByName(ticks, "angle_deg", 0));
  ASSERT_EQ(angle.size(), box.size());
  EXPECT_TRUE(std::isnan(angle.back()));  // the reading that caused the fault, as the engine saw it
  EXPECT_EQ(doubles(Mat_VarGetStructFieldByName(ticks, "u_tot_bar", 0)).front(), box.front().joint(0).u_total_bar);
  matvar_t* faults = Mat_VarGetStructFieldByName(ticks, "fault", 0);
  ASSERT_NE(faults, nullptr);
  ASSERT_EQ(faults->class_type, MAT_C_CELL);
  EXPECT_EQ(chars(Mat_VarGetCell(faults, static_cast<int>(box.size()) - 1)), "sensor-nan");
  EXPECT_EQ(chars(Mat_VarGetCell(faults, 0)), "none");
  EXPECT_EQ(chars(Mat_VarGetCell(Mat_VarGetStructFieldByName(ticks, "state", 0), static_cast<int>(box.size()) - 1)),
            "FAULT");
  Mat_VarFree(boxes);
  Mat_Close(file);
}

TEST_F(SessionExport, WritesMatV5ByDefaultAndV73OnRequest) {
  expect_mat_contents(export_session_mat(session_, dir_ / "v5.mat"), session_, MAT_FT_MAT5);
  expect_mat_contents(export_session_mat(session_, dir_ / "v73.mat", MatVersion::kV73), session_, MAT_FT_MAT73);
}

TEST_F(SessionExport, CsvHasTheBlackBoxWithTheIterationFilesNamesAndNamedCodes) {
  const std::vector<fs::path> files = export_session_csv(session_, dir_ / "out.csv");
  ASSERT_EQ(files.size(), 4u);
  EXPECT_EQ(files[3], dir_ / "out_blackbox.csv");
  const std::string text = testing::read_text(files[3]);
  const std::string header = text.substr(0, text.find('\n'));
  EXPECT_EQ(header.rfind("black_box,tick,time_s,sensor_time_s,state,fault,angle_deg,angle_setpoint_deg,", 0), 0u)
      << header;
  EXPECT_NE(header.find(",u_tot_bar,"), std::string::npos) << header;
  const std::string last_row = text.substr(text.rfind('\n', text.size() - 2) + 1);
  EXPECT_NE(last_row.find(",FAULT,sensor-nan,nan,"), std::string::npos) << last_row;
  EXPECT_EQ(last_row.substr(0, 2), "0,");
  // A session without faults has no black-box file.
  Session clean = session_;
  clean.black_boxes.clear();
  clean.manifest.black_boxes.clear();
  EXPECT_EQ(export_session_csv(clean, dir_ / "clean.csv").size(), 3u);
  EXPECT_FALSE(fs::exists(dir_ / "clean_blackbox.csv"));
}

TEST_F(SessionExport, ReadsLegacyBlackBoxesWithNumericCodes) {
  const std::vector<TickRecord>& box = session_.black_boxes[0];
  std::string legacy =
      "tick,time_s,sensor_time_s,state,fault,angle_deg,desired_deg,pressure_a_bar,pressure_b_bar,"
      "supply_bar,u_total_bar,pressure_a_setpoint_bar,pressure_b_setpoint_bar,inlet_a_duty,"
      "outlet_a_duty,inlet_b_duty,outlet_b_duty,sample,trial_id\n";
  const std::vector<Eigen::VectorXd> values = black_box_values(box);
  const std::vector<std::string> header = black_box_header(1);
  std::vector<CsvColumn> columns;
  for (std::size_t c = 0; c < values.size(); ++c) columns.push_back({header[c], &values[c]});
  std::string numeric;
  append_csv(numeric, columns);
  legacy += numeric.substr(numeric.find('\n') + 1);
  const std::vector<TickRecord> read = parse_black_box_csv(legacy, "old.csv", static_cast<int>(box.size()));
  ASSERT_EQ(read.size(), box.size());
  EXPECT_EQ(read.back().fault, FaultCode::kSensorNotANumber);
  EXPECT_EQ(read.back().state, EngineState::kFault);
  EXPECT_EQ(read.front().joint(0).u_total_bar, box.front().joint(0).u_total_bar);
  EXPECT_EQ(format_black_box_csv(read), format_black_box_csv(box));  // rewritten in today's vocabulary
  std::string bad = legacy;
  bad.replace(bad.find("\n") + 1, bad.size(), "x\n");
  EXPECT_THROW(parse_black_box_csv(bad, "old.csv", 1), InputError);
}

TEST_F(SessionExport, NeverReplacesAFileUnlessForced) {
  testing::write_text(dir_ / "x.mat", "precious");
  EXPECT_EQ(message_of([&] { export_session_mat(session_, dir_ / "x.mat"); }),
            (dir_ / "x.mat").string() + " exists already (--force replaces it)");
  EXPECT_EQ(testing::read_text(dir_ / "x.mat"), "precious");
  export_session_mat(session_, dir_ / "x.mat", MatVersion::kV5, true);
  EXPECT_NE(testing::read_text(dir_ / "x.mat"), "precious");

  // An existing sibling stops the CSV export before it writes anything.
  testing::write_text(dir_ / "y_summary.csv", "precious");
  EXPECT_NE(message_of([&] { export_session_csv(session_, dir_ / "y.csv"); }).find("y_summary.csv exists already"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "y.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "y_telemetry.csv"));
  EXPECT_EQ(testing::read_text(dir_ / "y_summary.csv"), "precious");
  EXPECT_EQ(export_session_csv(session_, dir_ / "y.csv", true).size(), 4u);
  EXPECT_NE(testing::read_text(dir_ / "y_summary.csv"), "precious");
}

TEST_F(SessionExport, NeverWritesIntoTheSessionItExportsEvenWhenForced) {
  const std::string manifest = testing::read_text(dir_ / "s" / session_layout::kManifest);
  const std::string trajectory = testing::read_text(dir_ / "s" / session_layout::kTrajectory);
  EXPECT_NE(
      message_of([&] { export_session_csv(session_, dir_ / "s" / "trajectory.csv", true); }).find("inside the session"),
      std::string::npos);
  EXPECT_NE(message_of([&] {
              export_session_mat(session_, dir_ / "s" / "iterations" / "x.mat", MatVersion::kV5, true);
            }).find("inside the session"),
            std::string::npos);
  EXPECT_EQ(testing::read_text(dir_ / "s" / session_layout::kTrajectory), trajectory);
  EXPECT_EQ(testing::read_text(dir_ / "s" / session_layout::kManifest), manifest);
  EXPECT_NO_THROW(load_session(dir_ / "s"));
}

TEST_F(SessionExport, RefusesAnotherExtensionAndAMissingFolder) {
  EXPECT_EQ(message_of([&] { export_session_mat(session_, dir_ / "x.csv"); }),
            "the output " + (dir_ / "x.csv").string() + " must end in .mat for this format (not .csv)");
  EXPECT_FALSE(fs::exists(dir_ / "x.csv"));
  EXPECT_EQ(message_of([&] { export_session_csv(session_, dir_ / "x.mat"); }).find("must end in .csv"),
            ("the output " + (dir_ / "x.mat").string() + " ").size());
  for (const MatVersion version : {MatVersion::kV5, MatVersion::kV73}) {
    EXPECT_EQ(message_of([&] { export_session_mat(session_, dir_ / "nowhere" / "x.mat", version); }),
              "cannot write " + (dir_ / "nowhere" / "x.mat").string() + ": the folder " + (dir_ / "nowhere").string() +
                  " does not exist");
  }
}

TEST_F(SessionExport, TheCommandLineSaysItInOneLineWithExitStatus2) {
  const std::string session = (dir_ / "s").string();
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--format", "mat", "--mat-version", "7.3", "--output",
                                 (dir_ / "no" / "x.mat").string()},
        {"--format", "mat", "--output", (dir_ / "x.csv").string()},
        {"--format", "csv", "--mat-version", "5", "--output", (dir_ / "x.csv").string()},
        {"--format", "csv", "--output", (dir_ / "s" / "manifest.json").string(), "--force"}}) {
    std::vector<std::string> command = {"sessions", "export", session};
    command.insert(command.end(), args.begin(), args.end());
    const ProcessResult result = run_bellows(command);
    EXPECT_EQ(result.exit_code, 2) << args[1];
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_EQ(result.err.rfind("bellows: ", 0), 0u) << result.err;
  }
  EXPECT_NO_THROW(load_session(dir_ / "s"));
  const ProcessResult first =
      run_bellows({"sessions", "export", session, "--format", "mat", "--output", (dir_ / "a.mat").string()});
  EXPECT_EQ(first.exit_code, 0) << first.err;
  const ProcessResult again =
      run_bellows({"sessions", "export", session, "--format", "mat", "--output", (dir_ / "a.mat").string()});
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_EQ(again.err, "bellows: " + (dir_ / "a.mat").string() + " exists already (--force replaces it)\n");
  const ProcessResult forced = run_bellows({"sessions", "export", session, "--format", "mat", "--mat-version", "7.3",
                                            "--force", "--output", (dir_ / "a.mat").string()});
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  mat_t* file = Mat_Open((dir_ / "a.mat").c_str(), MAT_ACC_RDONLY);
  ASSERT_NE(file, nullptr);
  EXPECT_EQ(Mat_GetVersion(file), MAT_FT_MAT73);
  Mat_Close(file);
}

}  // namespace
}  // namespace bellows
