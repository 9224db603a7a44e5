#include "app/plot_figures.hpp"

#include <algorithm>
#include <charconv>
#include <set>

#include "engine/base/errors.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/csv_table.hpp"
#include "sessions/iteration_files.hpp"

namespace bellows {
namespace fs = std::filesystem;
namespace {

// One size for every figure: a journal column at 300 dpi is about this wide.
constexpr const char* kPngTerminal = "set terminal pngcairo size 1200,800 noenhanced font ',12'";
constexpr const char* kSvgTerminal = "set terminal svg size 1200,800 noenhanced font 'sans,12'";
constexpr const char* kPdfTerminal = "set terminal pdfcairo size 8in,5.33in noenhanced font ',10'";

/// A gnuplot single-quoted string: '' stands for a quote inside.
std::string quoted(const std::string& text) {
  std::string out(1, '\'');
  for (char c : text) {
    if (c == '\'') out += '\'';
    if (c == '\n' || c == '\r') c = ' ';
    out += c;
  }
  out += '\'';
  return out;
}

std::string number(double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

/// A data block: one row per index, the given columns separated by spaces.
std::string data_block(const std::string& name, const std::vector<const Eigen::VectorXd*>& columns) {
  std::string out = "$";
  out += name;
  out += " << EOD\n";
  const Eigen::Index rows = columns.front()->size();
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (c > 0) out += ' ';
      out += number((*columns[c])(r));
    }
    out += '\n';
  }
  return out + "EOD\n";
}

std::string common_settings(const std::string& title, const std::string& xlabel, const std::string& ylabel) {
  return "set title " + quoted(title) + "\nset xlabel " + quoted(xlabel) + "\nset ylabel " + quoted(ylabel) +
         "\nset grid\nset key outside right top\n";
}

/// `plot` of the given "source using ..." clauses, each with its title.
std::string plot_command(const std::vector<std::pair<std::string, std::string>>& clauses) {
  std::string out = "plot ";
  for (std::size_t i = 0; i < clauses.size(); ++i) {
    if (i > 0) out += ", \\\n     ";
    out += clauses[i].first;
    out += " title ";
    out += quoted(clauses[i].second);
  }
  return out + "\n";
}

const IterationData& iteration_of(const Session& session, int iteration, const char* what) {
  if (iteration < 0 || iteration >= static_cast<int>(session.iterations.size())) {
    throw InputError(std::string(what) + " " + std::to_string(iteration) + ": the session has iterations 0 to " +
                     std::to_string(static_cast<int>(session.iterations.size()) - 1));
  }
  return session.iterations[static_cast<std::size_t>(iteration)];
}

Figure rms_figure(const Session& session, const FigureRequest& request) {
  const auto n = static_cast<Eigen::Index>(session.manifest.iterations.size());
  Eigen::VectorXd iteration(n), rms(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    iteration(i) = session.manifest.iterations[static_cast<std::size_t>(i)].summary.iteration;
    rms(i) = session.manifest.iterations[static_cast<std::size_t>(i)].summary.rms_deg;
  }
  Figure f{"rms", {}, data_block("rms", {&iteration, &rms}), {}};
  std::vector<std::pair<std::string, std::string>> clauses = {
      {"$rms using 1:2 with linespoints linewidth 2 pointtype 7", "bellows: " + session.manifest.name}};
  if (request.paper_rms && !request.paper_rms->empty()) {
    const auto m = static_cast<Eigen::Index>(request.paper_rms->size());
    Eigen::VectorXd paper_iteration(m), paper_rms(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      paper_iteration(i) = (*request.paper_rms)[static_cast<std::size_t>(i)].first;
      paper_rms(i) = (*request.paper_rms)[static_cast<std::size_t>(i)].second;
    }
    f.data += data_block("paper", {&paper_iteration, &paper_rms});
    clauses.push_back({"$paper using 1:2 with linespoints dashtype 2 pointtype 6", "paper"});
  }
  f.plot = common_settings("RMS tracking error per iteration", "iteration", "RMS error [deg]") +
           "set logscale y\nset format y '%g'\n" + plot_command(clauses);
  for (const auto& clause : clauses) f.series.push_back(clause.second);
  return f;
}

/// Data blocks $iteration_J (time_s, angle_deg, u_ilc_bar) of the chosen iterations.
std::string iteration_blocks(const Session& session, const std::vector<int>& iterations) {
  std::string out;
  for (int j : iterations) {
    const TrialSamples& s = iteration_of(session, j, "iteration").record.samples;
    const Eigen::VectorXd time_s = rounded_times(s.time_s), angle = degrees_of(s.angle_rad);
    out += data_block("iteration_" + std::to_string(j), {&time_s, &angle, &s.u_ilc_bar});
  }
  return out;
}

Figure angle_figure(const Session& session, const std::vector<int>& iterations) {
  const Trajectory& trajectory = session.trajectory;
  Eigen::VectorXd time_s(trajectory.angle_rad.size());
  for (Eigen::Index k = 0; k < time_s.size(); ++k) time_s(k) = static_cast<double>(k) * trajectory.sample_time_s;
  const Eigen::VectorXd times = rounded_times(time_s), angle = degrees_of(trajectory.angle_rad);
  Figure f{"angle", {}, data_block("setpoint", {&times, &angle}) + iteration_blocks(session, iterations), {}};
  std::vector<std::pair<std::string, std::string>> clauses = {{"$setpoint using 1:2 with lines linewidth 3 dashtype 2 lc rgb 'black'", "set point"}};
  for (int j : iterations) clauses.push_back({"$iteration_" + std::to_string(j) + " using 1:2 with lines linewidth 2", "iteration " + std::to_string(j)});
  f.plot = common_settings("Joint angle and set point: " + session.manifest.name, "time [s]", "angle [deg]") + plot_command(clauses);
  for (const auto& clause : clauses) f.series.push_back(clause.second);
  return f;
}

Figure correction_figure(const Session& session, const std::vector<int>& iterations) {
  Figure f{"u_ilc", {}, {}, {}};  // reuses the angle figure's $iteration_J blocks
  std::vector<std::pair<std::string, std::string>> clauses;
  for (int j : iterations) clauses.push_back({"$iteration_" + std::to_string(j) + " using 1:3 with steps linewidth 2", "iteration " + std::to_string(j)});
  f.plot = common_settings("Learned correction u_ilc: " + session.manifest.name, "time [s]", "u_ilc [bar]") + plot_command(clauses);
  for (const auto& clause : clauses) f.series.push_back(clause.second);
  return f;
}

Figure pressure_figure(const Session& session, int trial) {
  const TrialTicks& t = iteration_of(session, trial, "trial").record.ticks;
  const Eigen::VectorXd time_s = rounded_times(t.time_s);
  Figure f{"pressures", {}, data_block("pressures", {&time_s, &t.pressure_a_bar, &t.pressure_b_bar, &t.setpoint_a_bar,
                                                      &t.setpoint_b_bar, &t.supply_bar}), {}};
  const std::vector<std::pair<std::string, std::string>> clauses = {
      {"$pressures using 1:2 with lines linewidth 2 lc rgb '#1f77b4'", "p_A measured"},
      {"$pressures using 1:3 with lines linewidth 2 lc rgb '#d62728'", "p_B measured"},
      {"$pressures using 1:4 with steps dashtype 2 lc rgb '#1f77b4'", "p_A set point"},
      {"$pressures using 1:5 with steps dashtype 2 lc rgb '#d62728'", "p_B set point"},
      {"$pressures using 1:6 with lines lc rgb 'gray'", "supply"}};
  f.plot = common_settings("Pressures, iteration " + std::to_string(trial) + ": " + session.manifest.name, "time [s]",
                           "pressure [bar abs]") +
           plot_command(clauses);
  for (const auto& clause : clauses) f.series.push_back(clause.second);
  return f;
}

const char* terminal_of(const std::string& format) {
  if (format == "png") return kPngTerminal;
  if (format == "svg") return kSvgTerminal;
  if (format == "pdf") return kPdfTerminal;
  throw InputError("figure format must be png, svg or pdf, not '" + format + "'");
}

}  // namespace

std::vector<int> default_plot_iterations(int count) {
  std::set<int> chosen;
  if (count <= 0) return {};
  for (int j : {0, 1, count / 2, count - 1}) {
    if (j < count) chosen.insert(j);
  }
  return {chosen.begin(), chosen.end()};
}

std::vector<Figure> session_figures(const Session& session, const FigureRequest& request) {
  for (const std::string& format : request.formats) terminal_of(format);
  const int count = static_cast<int>(session.iterations.size());
  if (count == 0) throw InputError("session " + session.directory.string() + " has no iteration to plot");
  const std::vector<int> iterations = request.iterations.empty() ? default_plot_iterations(count) : request.iterations;
  return {rms_figure(session, request), angle_figure(session, iterations), correction_figure(session, iterations),
          pressure_figure(session, request.pressure_trial < 0 ? count - 1 : request.pressure_trial)};
}

std::vector<fs::path> figure_files(const std::vector<Figure>& figures, const std::vector<std::string>& formats,
                                   const fs::path& directory) {
  std::vector<fs::path> out;
  for (const Figure& figure : figures) {
    for (const std::string& format : formats) out.push_back(directory / (figure.name + "." + format));
  }
  return out;
}

std::string gnuplot_script(const std::vector<Figure>& figures, const std::vector<std::string>& formats) {
  std::string out = "# Written by bellows sessions plot; `gnuplot figures.gp` in this folder draws them again.\n";
  for (const Figure& figure : figures) out += figure.data;
  for (const Figure& figure : figures) {
    for (const std::string& format : formats) {
      out += "\n# " + figure.name + "." + format + "\nreset\n" + terminal_of(format) + "\nset output " +
             quoted(figure.name + "." + format) + "\n" + figure.plot + "unset output\n";
    }
  }
  return out;
}

std::vector<std::pair<double, double>> read_paper_rms(const fs::path& path) {
  const std::vector<Eigen::VectorXd> columns = parse_csv(read_file(path), {"iteration", "rms_deg"}, path.string());
  std::vector<std::pair<double, double>> out;
  for (Eigen::Index i = 0; i < columns[0].size(); ++i) out.emplace_back(columns[0](i), columns[1](i));
  return out;
}

}  // namespace bellows
