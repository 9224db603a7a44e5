// The built-in trajectories (declared in engine/trial/trajectory.hpp): the paper's (reference-system.md
// section 6), two single-joint exercises, and the multi-joint ones of multi-joint.md section 3.
#include <cmath>
#include <numbers>

#include "engine/base/errors.hpp"
#include "engine/trial/trajectory.hpp"
#include "engine/base/units.hpp"

namespace bellows {
namespace {

// The paper's moves (reference-system.md section 6): 0.2 s trapezoids at 12000 deg/s^2 peak.
constexpr double kPaperMove_s = 0.2, kPaperAcceleration_deg_per_s2 = 12000.0;
constexpr double kPaperDuration_s = 8.0;

/// Moves through `angles_deg` (the first is where the joint starts): move i goes from angle i to
/// angle i + 1, starting at `starts_s[i]` + `delay_s`.
JointMoves moves_through(const std::vector<double>& angles_deg, const std::vector<double>& starts_s, double move_s,
                         double peak_acceleration_deg_per_s2, double delay_s = 0.0) {
  JointMoves joint{angles_deg.front(), {}};
  for (std::size_t i = 0; i + 1 < angles_deg.size() && i < starts_s.size(); ++i) {
    joint.moves.push_back(
        {starts_s[i] + delay_s, angles_deg[i], angles_deg[i + 1], move_s, peak_acceleration_deg_per_s2});
  }
  return joint;
}

/// The paper's six moves between +-30 deg, `delay_s` later than the paper (paper3's wrist: 0.3 s).
JointMoves paper_moves(double delay_s = 0.0) {
  return moves_through({0, 30, -30, 30, -30, 30, 0}, {0.6, 1.6, 2.6, 3.6, 4.6, 5.6}, kPaperMove_s,
                       kPaperAcceleration_deg_per_s2, delay_s);
}

/// multi-joint.md section 3: the shoulder's four 0.3 s moves, the paper's move shape (the same
/// trapezoid, the same peak acceleration).
JointMoves shoulder_moves() {
  constexpr double kShoulderMove_s = 0.3;
  return moves_through({0, 20, -20, 20, 0}, {0.6, 2.0, 3.4, 4.8}, kShoulderMove_s, kPaperAcceleration_deg_per_s2);
}

constexpr double kWristDelay_s = 0.3;  // paper3's wrist follows the elbow this much later

Trajectory sine(double sample_time_s) {
  constexpr double kDuration_s = 8.0, kAmplitude_deg = 30.0, kFrequency_Hz = 0.5, kFade_s = 1.0;
  const int samples = static_cast<int>(std::lround(kDuration_s / sample_time_s));
  Trajectory trajectory{"sine", sample_time_s, {Eigen::VectorXd(samples + 1)}};
  for (int k = 0; k <= samples; ++k) {
    const double t = k * sample_time_s;
    const double edge = std::min(t, kDuration_s - t);
    const double fade = edge >= kFade_s ? 1.0 : 0.5 * (1.0 - std::cos(std::numbers::pi * edge / kFade_s));
    trajectory.joint(0)(k) = fade * kAmplitude_deg * kRadPerDeg * std::sin(2.0 * std::numbers::pi * kFrequency_Hz * t);
  }
  return trajectory;
}

struct LibraryEntry {
  const char* name;
  int joints;
  const char* description;
  Trajectory (*build)(double sample_time_s);
};

// The library, described once: the chooser, the help texts and the lookups read this table.
const LibraryEntry kLibrary[] = {
    {"paper", 1, "8 s, six 0.2 s moves between +-30 deg (the paper's reference)",
     [](double t) { return trajectory_from_joint_moves("paper", {paper_moves()}, kPaperDuration_s, t); }},
    {"steps", 1, "10 s, staircase 0 -> 20 -> 40 -> -20 -> -40 -> 0 deg, 0.3 s moves",
     [](double t) {
       constexpr double kSlow_s = 0.3, kSlowAcceleration_deg_per_s2 = 4000.0;
       return trajectory_from_joint_moves(
           "steps",
           {moves_through({0, 20, 40, -20, -40, 0}, {0.5, 2.0, 3.5, 5.0, 6.5}, kSlow_s, kSlowAcceleration_deg_per_s2)},
           10.0, t);
     }},
    {"sine", 1, "8 s, 30 deg amplitude at 0.5 Hz with a 1 s raised-cosine fade in and out", sine},
    {"paper2", 2, "8 s, 2 joints: shoulder 0 -> 20 -> -20 -> 20 -> 0 deg (0.3 s moves), elbow the paper's",
     [](double t) {
       return trajectory_from_joint_moves("paper2", {shoulder_moves(), paper_moves()}, kPaperDuration_s, t);
     }},
    {"paper3", 3, "8 s, 3 joints: paper2, and the wrist does the paper's moves 0.3 s after the elbow",
     [](double t) {
       return trajectory_from_joint_moves("paper3", {shoulder_moves(), paper_moves(), paper_moves(kWristDelay_s)},
                                          kPaperDuration_s, t);
     }},
};

const LibraryEntry& library_entry(const std::string& name) {
  for (const LibraryEntry& entry : kLibrary) {
    if (name == entry.name) return entry;
  }
  throw InputError("unknown trajectory '" + name + "' (library: " + trajectory_library_summary() + ")");
}

}  // namespace

std::vector<std::string> trajectory_library_names() {
  std::vector<std::string> names;
  for (const LibraryEntry& entry : kLibrary) names.emplace_back(entry.name);
  return names;
}

std::string trajectory_library_description(const std::string& name) { return library_entry(name).description; }

int trajectory_library_joints(const std::string& name) { return library_entry(name).joints; }

std::string trajectory_library_summary() {
  std::string summary;
  for (const LibraryEntry& entry : kLibrary) {
    summary += (summary.empty() ? "" : ", ") + std::string(entry.name);
    if (entry.joints > 1) summary += " (" + std::to_string(entry.joints) + " joints)";
  }
  return summary;
}

Trajectory library_trajectory(const std::string& name, double sample_time_s) {
  return library_entry(name).build(sample_time_s);
}

}  // namespace bellows
