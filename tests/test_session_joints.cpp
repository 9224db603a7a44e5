// Sessions of an arm with several joints (issue 14): a 2- and a 3-joint session, simulated in
// process on the J-joint simulated arm (arm2, arm3), is saved and loaded back with every joint's
// columns as recorded (to the file's precision), its manifest counting the joints and its resume
// state holding every joint's controllers; the CSV and MAT exports carry every joint (the MAT file
// read back by scipy); a one-joint record is written exactly as always; the chain's state goes
// through the manifest's JSON bit for bit, and a run saved by RunRecording and resumed continues bit
// for bit; a manifest or file that lies about the joints is refused in one line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "app/arm_chain_state_json.hpp"
#include "app/run_recording.hpp"
#include "devices/simulated_arm_chain.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/rt/engine_driver.hpp"
#include "engine/model/pneumatic_arm_chain_parameters.hpp"
#include "engine/base/units.hpp"
#include "sessions/iteration_files.hpp"
#include "sessions/json_reader.hpp"
#include "sessions/manifest_json.hpp"
#include "sessions/record_columns.hpp"
#include "sessions/session_export.hpp"
#include "sessions/session_layout.hpp"
#include "sessions/session_store.hpp"
#include "tests/session_test_support.hpp"

namespace bellows {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using testing::TempDir;

/// The J-joint simulated arm driven by the engine on a simulated clock.
struct JointRig {
  JointRig(const Configuration& configuration, std::uint64_t seed)
      : config(configuration),
        arm(pneumatic_chain_of(config.plant, config.arm), seed),
        core(arm, config.controller, config.timing, config.safety),
        clock(core, arm) {}

  /// One trial of `trajectory` with `correction` (N x J); the record comes back complete.
  TrialRecord trial(const Trajectory& trajectory, const Eigen::MatrixXd& correction, std::uint32_t id) {
    TrialRecord record;
    record.prepare(trajectory.learning_samples(), config.timing.ticks_per_sample, trajectory.joints());
    const int settle_ticks = static_cast<int>(std::lround(config.timing.settle_s / config.timing.tick_s));
    EXPECT_TRUE(core.send(EngineCommand::start_trial(trajectory, correction, record, settle_ticks, id)));
    clock.step(settle_ticks + static_cast<long>(trajectory.learning_samples()) * config.timing.ticks_per_sample + 2);
    EngineEvent event;
    while (core.poll_event(event)) EXPECT_NE(event.kind, EventKind::kFault) << fault_name(event.fault);
    EXPECT_TRUE(record.complete) << "trial " << id;
    return record;
  }

  Configuration config;
  SimulatedArmChain arm;
  EngineCore core;
  SimulatedClock clock;
};

Configuration joint_configuration(const char* preset) {
  Configuration config = testing::short_configuration();
  config.arm.preset = preset;
  return config;
}

/// The first 2 s of the library's `name` (paper2, paper3): every joint, 100 learning samples.
Trajectory joint_trajectory(const std::string& name, double sample_time_s) {
  Trajectory trajectory = library_trajectory(name, sample_time_s);
  constexpr Eigen::Index kRows = 101;
  trajectory.name = name + "-head";
  for (Eigen::VectorXd& joint : trajectory.angles_rad) joint = joint.head(kRows).eval();
  return trajectory;
}

/// A correction that differs per joint and per iteration (the learning's job is not tested here).
Eigen::MatrixXd joint_correction(int samples, int joints, int iteration) {
  Eigen::MatrixXd u(samples, joints);
  for (int j = 0; j < joints; ++j) {
    for (int k = 0; k < samples; ++k) u(k, j) = 0.01 * iteration * std::sin(0.1 * k + j) / (j + 1);
  }
  return u;
}

IterationSummary joint_summary(int iteration, const TrialRecord& record) {
  IterationSummary summary;
  summary.iteration = iteration;
  summary.rms_deg = record.rms_error_deg();
  summary.max_abs_error_deg = record.max_abs_error_deg();
  return summary;
}

/// A session of `trials` iterations on the `preset` arm, as a run would save it.
Session simulate_joint_session(const char* preset, const std::string& trajectory_name, int trials) {
  JointRig rig(joint_configuration(preset), 3);
  const Trajectory trajectory = joint_trajectory(trajectory_name, rig.config.timing.sample_s());
  const int n = trajectory.learning_samples(), joints = trajectory.joints();
  Session session;
  SessionManifest& m = session.manifest;
  m.program_version = program_version();
  m.name = preset;
  m.device = rig.arm.name();
  m.device_info = {{"seed", 3}};
  m.started_utc = utc_now();
  m.updated_utc = m.started_utc;
  m.configuration = rig.config;
  m.joints = joints;
  m.trajectory_name = trajectory.name;
  m.trajectory_samples = n;
  session.trajectory = trajectory;
  EXPECT_TRUE(rig.core.send(EngineCommand::select_trajectory(trajectory)));
  EXPECT_TRUE(rig.core.send(EngineCommand::of(CommandKind::kArm)));
  rig.clock.step();
  for (int i = 0; i < trials; ++i) {
    const TrialRecord record = rig.trial(trajectory, joint_correction(n, joints, i), static_cast<std::uint32_t>(i + 1));
    IterationData data{record, {}};
    data.set_next_corrections(joint_correction(n, joints, i + 1));
    session.iterations.push_back(std::move(data));
    m.iterations.push_back({joint_summary(i, record), utc_now()});
    m.resume = ResumeState{rig.core.control().state(), chain_state_to_json(rig.arm), rig.clock.ticks()};
  }
  return session;
}

/// Where `record` keeps `column` for joint `joint`: the joint's own, the record's shared one, or
/// nothing (the correction learned, a column of IterationData).
template <typename Joint>
const Eigen::VectorXd* column_values(const TrialRecord& record, const Joint& of_joint,
                                     const RecordColumn<Joint>& column) {
  if (column.member != nullptr) return &(of_joint.*column.member);
  if (column.shared != nullptr) return &(record.*column.shared);
  return nullptr;
}

/// `a` and `b` agree as a file keeps them: angles through degrees (an ulp at most), the rest exactly.
template <typename Joint>
void expect_columns_equal(const TrialRecord& a, const Joint& a_joint, const TrialRecord& b, const Joint& b_joint,
                          const std::vector<RecordColumn<Joint>>& columns, int joint) {
  for (const RecordColumn<Joint>& column : columns) {
    const Eigen::VectorXd* x = column_values(a, a_joint, column);
    const Eigen::VectorXd* y = column_values(b, b_joint, column);
    if (x == nullptr || y == nullptr) continue;
    ASSERT_EQ(x->size(), y->size()) << column.name << " of joint " << joint + 1;
    const double tolerance = column.scale == ColumnScale::kAsIs ? 0.0 : 1e-12;
    EXPECT_LE((*x - *y).cwiseAbs().maxCoeff(), tolerance) << column.name << " of joint " << joint + 1;
  }
}

void expect_columns_equal(const TrialRecord& a, const TrialRecord& b, int joint) {
  expect_columns_equal(a, a.joint_samples(joint), b, b.joint_samples(joint), samples_record_columns(), joint);
  expect_columns_equal(a, a.joint_ticks(joint), b, b.joint_ticks(joint), telemetry_record_columns(), joint);
}

/// The header line of `file`.
std::string header_of_file(const fs::path& file) {
  const std::string text = testing::read_text(file);
  return text.substr(0, text.find('\n'));
}

class JointSessions : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(JointSessions, RoundTripEveryJointAndExportIt) {
  const auto [preset, trajectory_name] = GetParam();
  TempDir dir;
  const Session saved = simulate_joint_session(preset, trajectory_name, 2);
  const int joints = saved.trajectory.joints();
  ASSERT_EQ(saved.iterations[0].record.joint_count(), joints);
  save_session(saved, dir / "s");
  const Session loaded = load_session(dir / "s");

  // The manifest counts the joints; the trajectory has one column per joint.
  const Json manifest = Json::parse(testing::read_text(dir / "s" / session_layout::kManifest));
  EXPECT_EQ(manifest["trajectory"]["joints"], joints);
  EXPECT_EQ(manifest["schema_version"], kSessionSchemaVersion);
  EXPECT_EQ(loaded.manifest.joints, joints);
  std::string trajectory_header = "time_s";
  for (int j = 1; j <= joints; ++j) trajectory_header += ",q" + std::to_string(j) + "_deg";
  EXPECT_EQ(header_of_file(dir / "s" / session_layout::kTrajectory), trajectory_header);
  ASSERT_EQ(loaded.trajectory.joints(), joints);
  for (int j = 0; j < joints; ++j) {
    const Eigen::VectorXd difference = loaded.trajectory.joint(j) - saved.trajectory.joint(j);
    EXPECT_LE(difference.cwiseAbs().maxCoeff(), 1e-12) << "joint " << j + 1;
  }

  // Every joint's columns, and its correction, read back.
  const std::string samples_header_line = header_of_file(dir / "s" / session_layout::samples_file(0));
  EXPECT_EQ(samples_header_line.rfind("time_s,angle_setpoint_deg,angle_deg,", 0), 0u) << samples_header_line;
  EXPECT_NE(samples_header_line.find(",angle_deg_j" + std::to_string(joints) + ","), std::string::npos);
  EXPECT_NE(
      header_of_file(dir / "s" / session_layout::telemetry_file(0)).find("inlet_a_duty_j" + std::to_string(joints)),
      std::string::npos);
  ASSERT_EQ(loaded.iterations.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    ASSERT_EQ(loaded.iterations[i].record.joint_count(), joints);
    for (int j = 0; j < joints; ++j) expect_columns_equal(loaded.iterations[i].record, saved.iterations[i].record, j);
    EXPECT_EQ(loaded.iterations[i].next_corrections_bar(), saved.iterations[i].next_corrections_bar());
  }
  // The resume state holds every joint's controllers, each alike (schema version 2).
  const Json written = Json::parse(testing::read_text(dir / "s" / session_layout::kManifest));
  EXPECT_EQ(written["schema_version"], 2);
  EXPECT_EQ(written["resume"]["controller"]["joints"].size(), static_cast<std::size_t>(joints));
  EXPECT_FALSE(written["resume"]["controller"].contains("pid")) << "no joint is kept apart";
  const ControlCore::State& state = *loaded.manifest.resume->controller;
  const ControlCore::State& recorded = *saved.manifest.resume->controller;
  EXPECT_EQ(state.joint_count, joints);
  for (int j = 0; j < joints; ++j) {
    const auto& a = state.joints[static_cast<std::size_t>(j)];
    const auto& b = recorded.joints[static_cast<std::size_t>(j)];
    EXPECT_EQ(a.pid.integral_s, b.pid.integral_s) << "joint " << j + 1;
    EXPECT_EQ(a.pressure_a.sum_bar, b.pressure_a.sum_bar) << "joint " << j + 1;
    EXPECT_EQ(a.setpoints.b_bar, b.setpoints.b_bar) << "joint " << j + 1;
    EXPECT_EQ(a.hold_rad, b.hold_rad) << "joint " << j + 1;
    EXPECT_NE(a.pid.integral_s, 0.0) << "joint " << j + 1 << "'s controller ran";
  }

  // The CSV export stacks every joint's columns; its last joint's angle is the file's.
  const std::vector<fs::path> csv = export_session_csv(loaded, dir / "out.csv");
  const std::string stacked_header = header_of_file(csv[0]);
  EXPECT_EQ(stacked_header, "iteration," + samples_header_line);
  EXPECT_EQ(header_of_file(csv[1]), "iteration," + header_of_file(dir / "s" / session_layout::telemetry_file(0)));
  const std::string exported = testing::read_text(csv[0]);
  const std::string file = testing::read_text(dir / "s" / session_layout::samples_file(1));
  const std::string first_row_of_iteration_1 =
      file.substr(file.find('\n') + 1, file.find('\n', file.find('\n') + 1) - file.find('\n'));
  EXPECT_NE(exported.find("\n1," + first_row_of_iteration_1), std::string::npos);

  // The MAT export, read by scipy: every joint's samples and telemetry, the trajectory's columns.
  export_session_mat(loaded, dir / "out.mat");
  const std::string script = R"(
import sys
from scipy.io import loadmat
m = loadmat(sys.argv[1], squeeze_me=True, struct_as_record=False)
it = m["iterations"][1]
j = int(sys.argv[2])
print(len(m["iterations"]), it.samples.__dict__["angle_deg_j%d" % j][5], it.telemetry.__dict__["outlet_b_duty_j%d" % j][7],
      it.samples.__dict__["u_ilc_next_bar_j%d" % j][3], m["session"].trajectory.__dict__["q%d_deg" % j][int(sys.argv[3])])
)";
  testing::write_text(dir / "read.py", script);
  const int last = joints - 1;
  Eigen::Index moved = 0;  // the sample where the last joint is farthest from 0
  loaded.trajectory.joint(last).cwiseAbs().maxCoeff(&moved);
  FILE* pipe = ::popen(("/usr/bin/python3 " + (dir / "read.py").string() + " " + (dir / "out.mat").string() + " " +
                        std::to_string(joints) + " " + std::to_string(moved) + " 2>&1")
                           .c_str(),
                       "r");
  ASSERT_NE(pipe, nullptr);
  char buffer[512] = {};
  const std::size_t got = std::fread(buffer, 1, sizeof buffer - 1, pipe);
  ::pclose(pipe);
  const TrialRecord& record = loaded.iterations[1].record;
  std::istringstream read(std::string(buffer, got));
  int count = 0;
  double angle = 0, duty = 0, next = 0, trajectory_deg = 0;
  read >> count >> angle >> duty >> next >> trajectory_deg;
  ASSERT_FALSE(read.fail()) << std::string(buffer, got);
  EXPECT_EQ(count, 2);
  EXPECT_NEAR(angle, record.joint_samples(last).angle_rad(5) / kRadPerDeg, 1e-9);
  EXPECT_EQ(duty, record.joint_ticks(last).outlet_b(7));
  EXPECT_EQ(next, loaded.iterations[1].next_corrections_bar()(3, last));
  EXPECT_NEAR(trajectory_deg, loaded.trajectory.joint(last)(moved) / kRadPerDeg, 1e-9);
  EXPECT_NE(trajectory_deg, 0.0) << "the last joint moves by then";
}

INSTANTIATE_TEST_SUITE_P(Arms, JointSessions,
                         ::testing::Values(std::pair{"arm2", "paper2"}, std::pair{"arm3", "paper3"}),
                         [](const auto& arm) { return std::string(arm.param.first); });

TEST(JointSessionFiles, OneJointIsWrittenAsAlways) {
  // The headers of every session saved so far (the fixtures hold them too), and no joint count in
  // a one-joint manifest or resume state.
  EXPECT_EQ(samples_header(1),
            (std::vector<std::string>{"time_s", "angle_setpoint_deg", "angle_deg", "error_deg", "u_pid_bar",
                                      "u_ilc_bar", "u_tot_bar", "pressure_a_bar", "pressure_b_bar",
                                      "pressure_a_setpoint_bar", "pressure_b_setpoint_bar", "u_ilc_next_bar"}));
  EXPECT_EQ(telemetry_header(1),
            (std::vector<std::string>{"time_s", "angle_deg", "pressure_a_bar", "pressure_b_bar", "supply_bar",
                                      "pressure_a_setpoint_bar", "pressure_b_setpoint_bar", "inlet_a_duty",
                                      "outlet_a_duty", "inlet_b_duty", "outlet_b_duty"}));
  EXPECT_EQ(trajectory_header(1), (std::vector<std::string>{"time_s", "angle_deg"}));
  const Session one = testing::simulate_session(1);
  const Json manifest = manifest_to_json(one.manifest);
  EXPECT_FALSE(manifest["trajectory"].contains("joints"));
  EXPECT_FALSE(manifest["resume"]["controller"].contains("joints"));
  EXPECT_TRUE(manifest["resume"]["controller"].contains("pid")) << "joint 1's fields, as always";
  EXPECT_EQ(manifest["schema_version"], 1);
}

TEST(JointSessionFiles, EveryColumnIsDocumented) {
  const std::string docs = testing::read_text(fs::path(BELLOWS_SOURCE_DIR) / "docs" / "session-format.md");
  for (const auto& column : samples_record_columns())
    EXPECT_NE(docs.find("`" + std::string(column.name) + "`"), std::string::npos) << column.name;
  for (const auto& column : telemetry_record_columns())
    EXPECT_NE(docs.find(std::string(column.name)), std::string::npos) << column.name;
}

TEST(JointSessionState, TheChainsStateGoesThroughTheManifestBitForBit) {
  const Configuration config = joint_configuration("arm3");
  SimulatedArmChain arm(pneumatic_chain_of(config.plant, config.arm), 5);
  const auto drive = [](SimulatedArmChain& chain, int steps) {
    for (int i = 0; i < steps; ++i) {
      ValveCommand command;
      command.joint_count = chain.joints();
      for (int j = 0; j < chain.joints(); ++j) {
        command.joint[static_cast<std::size_t>(j)].inlet_duty = {0.3 + 0.1 * j, 0.1};
        command.joint[static_cast<std::size_t>(j)].outlet_duty = {0.05, 0.2 * (i % 3)};
      }
      chain.write_valves(command);
      chain.advance(0.005);
      (void)chain.read_sensors();
    }
  };
  drive(arm, 400);
  const std::string text = chain_state_to_json(arm).dump(2);  // as the manifest holds it
  SimulatedArmChain resumed(pneumatic_chain_of(config.plant, config.arm), 99);
  restore_chain_state(resumed, Json::parse(text), "test");
  drive(arm, 300);
  drive(resumed, 300);
  const PneumaticArmChain::State a = arm.chain().state(), b = resumed.chain().state();
  EXPECT_EQ(a.time_s, b.time_s);
  EXPECT_EQ(a.angle_rad, b.angle_rad);
  EXPECT_EQ(a.velocity_rad_per_s, b.velocity_rad_per_s);
  EXPECT_EQ(a.creep_rad, b.creep_rad);
  EXPECT_EQ(a.chamber_Pa, b.chamber_Pa);
  EXPECT_EQ(a.noise, b.noise);
  const SensorReading ra = arm.read_sensors(), rb = resumed.read_sensors();
  for (int j = 0; j < 3; ++j) {
    EXPECT_EQ(ra.joint[static_cast<std::size_t>(j)].angle_rad, rb.joint[static_cast<std::size_t>(j)].angle_rad);
    EXPECT_EQ(ra.joint[static_cast<std::size_t>(j)].chamber_bar, rb.joint[static_cast<std::size_t>(j)].chamber_bar);
  }
  // Another arm's state is refused in one line, naming the field.
  SimulatedArmChain two(pneumatic_chain_of(config.plant, ArmParameters{"arm2"}), 5);
  try {
    restore_chain_state(two, Json::parse(text), "session S: manifest.json");
    ADD_FAILURE() << "a 3-joint state restored into a 2-joint arm";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "session S: manifest.json: /resume/device/joints: the session's arm has 3 joints, this arm 2");
  }
}

TEST(JointSessionState, ARunSavedAndResumedContinuesBitForBit) {
  TempDir dir;
  const Configuration config = joint_configuration("arm2");
  const Trajectory trajectory = joint_trajectory("paper2", config.timing.sample_s());
  const int n = trajectory.learning_samples(), joints = trajectory.joints();
  RunOptions options;
  options.data_dir = dir.path().string();
  options.session_name = "arm2-run";
  options.iterations = 2;
  JointRig rig(config, 11);
  TrialRecord continued;
  {
    RunRecording recording(options);
    recording.start(config, trajectory, rig.arm.name(), 11, 2, {{"seed", 11}}, "configuration");
    ASSERT_TRUE(rig.core.send(EngineCommand::select_trajectory(trajectory)));
    ASSERT_TRUE(rig.core.send(EngineCommand::of(CommandKind::kArm)));
    rig.clock.step();
    for (int i = 0; i < 2; ++i) {
      const TrialRecord record =
          rig.trial(trajectory, joint_correction(n, joints, i), static_cast<std::uint32_t>(i + 1));
      recording.save(record, joint_correction(n, joints, i + 1), joint_summary(i, record), &rig.arm, rig.core,
                     &rig.clock);
    }
    continued = rig.trial(trajectory, joint_correction(n, joints, 2), 3);
  }
  options.resume_dir = (dir / "arm2-run").string();
  {
    RunRecording resuming(options);
    ASSERT_TRUE(resuming.resuming());
    JointRig again(config, 11);
    resuming.restore(&again.arm, again.core, &again.clock);
    EXPECT_EQ(resuming.resumed_corrections_bar(), joint_correction(n, joints, 2));
    EXPECT_EQ(resuming.resumed_history().size(), 2u);
    const long settle_ticks = std::lround(config.timing.settle_s / config.timing.tick_s);
    EXPECT_EQ(again.clock.ticks(), rig.clock.ticks() - (n * config.timing.ticks_per_sample + settle_ticks + 2));
    const TrialRecord resumed = again.trial(trajectory, resuming.resumed_corrections_bar(), 3);
    for (int j = 0; j < joints; ++j) {
      EXPECT_EQ(resumed.joint_samples(j).angle_rad, continued.joint_samples(j).angle_rad) << "joint " << j + 1;
      EXPECT_EQ(resumed.joint_ticks(j).pressure_b_bar, continued.joint_ticks(j).pressure_b_bar) << "joint " << j + 1;
      EXPECT_EQ(resumed.joint_samples(j).u_pid_bar, continued.joint_samples(j).u_pid_bar) << "joint " << j + 1;
    }
  }
  // An arm of other joints cannot continue it: one line says why.
  RunRecording other(options);
  JointRig three(joint_configuration("arm3"), 11);
  try {
    other.restore(&three.arm, three.core, &three.clock);
    ADD_FAILURE() << "a 2-joint session resumed on a 3-joint arm";
  } catch (const InputError& error) {
    EXPECT_NE(
        std::string(error.what()).find("was recorded with an arm of 2 joints; this run drives a simulated arm of 3"),
        std::string::npos)
        << error.what();
  }
}

/// The first line of the error loading `directory` throws (InputError), or "" when it loads.
std::string joint_load_error(const fs::path& directory) {
  try {
    load_session(directory);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(JointSessionDamage, LiesAboutTheJointsAreRefusedInOneLine) {
  TempDir dir;
  save_session(simulate_joint_session("arm2", "paper2", 1), dir / "s");
  const fs::path manifest_path = dir / "s" / session_layout::kManifest;
  const std::string original = testing::read_text(manifest_path);
  const auto with_manifest = [&](const std::function<void(Json&)>& edit) {
    Json manifest = Json::parse(original);
    edit(manifest);
    testing::write_text(manifest_path, manifest.dump(2) + "\n");
    const std::string error = joint_load_error(dir / "s");
    testing::write_text(manifest_path, original);
    return error;
  };
  const auto expect_one_line = [](const std::string& error, const std::string& wanted) {
    EXPECT_NE(error.find(wanted), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  };
  expect_one_line(with_manifest([](Json& m) { m["trajectory"]["joints"] = 9; }),
                  "manifest.json: /trajectory/joints: expected a whole number in [1, 4], found 9");
  // A manifest claiming 3 joints of 2-joint files: the resume state lacks joint 3's controllers...
  expect_one_line(with_manifest([](Json& m) { m["trajectory"]["joints"] = 3; }),
                  "/resume/controller/joints: expected 3 entries (one per joint of the session's 3), found 2");
  // ...and given them, the trajectory file has two joints' columns.
  expect_one_line(with_manifest([](Json& m) {
                    m["trajectory"]["joints"] = 3;
                    Json& all = m["resume"]["controller"]["joints"];
                    all.push_back(all[0]);
                  }),
                  "trajectory.csv: line 1: the header must be 'time_s,q1_deg,q2_deg,q3_deg'");
  // The resume state without joint 2's controllers.
  expect_one_line(with_manifest([](Json& m) { m["resume"]["controller"]["joints"].erase(1); }),
                  "/resume/controller/joints: expected 2 entries (one per joint of the session's 2), found 1");
  // An iteration file without joint 2's columns (a joint's data missing), its digest updated.
  const fs::path samples = dir / "s" / session_layout::samples_file(0);
  const Session loaded = load_session(dir / "s");
  TrialRecord one_joint = loaded.iterations[0].record;
  one_joint.joints.resize(1);
  testing::write_text(samples, format_samples_csv(one_joint, loaded.iterations[0].next_corrections_bar()));
  const std::string error = with_manifest([](Json& m) { m["iterations"][0].erase("samples_sha256"); });
  expect_one_line(error, "iterations/iteration_0000.csv: line 1: the header must be 'time_s,angle_setpoint_deg,");
  expect_one_line(error, "u_ilc_next_bar_j2'");
}

}  // namespace
}  // namespace bellows
