#include "app/plot_figures.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>

#include "app/plot_layout.hpp"
#include "app/plot_style.hpp"
#include "engine/base/errors.hpp"
#include "sessions/atomic_file.hpp"
#include "sessions/csv_table.hpp"
#include "sessions/iteration_files.hpp"

namespace bellows {
namespace fs = std::filesystem;
namespace {

/// A gnuplot single-quoted string: '' stands for a quote inside.
std::string gp_quoted(const std::string& text) {
  std::string out(1, '\'');
  for (char c : text) {
    if (c == '\'') out += '\'';
    if (c == '\n' || c == '\r') c = ' ';
    out += c;
  }
  out += '\'';
  return out;
}

std::string gp_number(double value) {
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
      out += gp_number((*columns[c])(r));
    }
    out += '\n';
  }
  return out + "EOD\n";
}

/// One curve of a figure: what gnuplot draws, its legend entry ("": none) and the points it covers.
struct Curve {
  std::string source;  // "$block using 1:2 with lines ..."
  std::string title;
  SeriesPoints points;
};

/// A figure from its curves: labels, the fitted layout, then the plot command, the curves drawn in
/// order; those listed in `on_top` (a set point) are drawn last but keep their place in the legend.
struct FigureBuilder {
  const FigureStyle& style;
  std::string title, xlabel, ylabel;
  AxisRange x;
  bool log_y = false;
  std::string extra;  // more settings (ticks, a zero line)
  std::vector<Curve> curves;
  std::vector<bool> on_top;
  std::string legend_heading = {};  // the legend's own title (plain text, no quote)

  void add(Curve curve, bool top = false) {
    curves.push_back(std::move(curve));
    on_top.push_back(top);
  }

  Figure build(std::string name, std::string data) const {
    Figure f{std::move(name), {}, std::move(data), {}};
    LegendSize legend;
    std::vector<SeriesPoints> points;
    for (const Curve& c : curves) {
      if (!c.title.empty()) {
        f.series.push_back(c.title);
        ++legend.rows;
        legend.widest_title = std::max(legend.widest_title, static_cast<int>(c.title.size()));
      }
      if (c.points.x != nullptr) points.push_back(c.points);
    }
    legend.heading_chars = static_cast<int>(legend_heading.size());
    PlotLayout layout = plot_layout(points, x, legend, style, log_y);
    layout.key_heading = legend_heading;
    std::string& p = f.plot;
    if (style.titles && !title.empty()) p += "set title " + gp_quoted(title) + " noenhanced\n";
    p += "set xlabel " + gp_quoted(xlabel) + "\nset ylabel " + gp_quoted(ylabel) + "\n";
    p += "set grid linetype 1 linecolor rgb '#dddddd' linewidth 0.5\nset border linewidth 0.8\nset tics nomirror out "
         "scale 0.6\n";
    p += "set border 3\n";
    p += layout_commands(layout);
    if (log_y) p += "set logscale y\n" + log_tics(layout.y) + "set format y '%g'\n";
    p += extra;
    std::vector<std::string> clauses;
    for (std::size_t i = 0; i < curves.size(); ++i) {
      const Curve& c = curves[i];
      if (on_top[i]) {
        // Its legend entry here (a keyentry of the same look), the curve itself after the others.
        const std::size_t with = c.source.find(" with ");
        clauses.push_back("keyentry" + c.source.substr(with) + " title " + gp_quoted(c.title) + " noenhanced");
      } else {
        clauses.push_back(c.source + (c.title.empty() ? " notitle" : " title " + gp_quoted(c.title) + " noenhanced"));
      }
    }
    for (std::size_t i = 0; i < curves.size(); ++i) {
      if (on_top[i]) clauses.push_back(curves[i].source + " notitle");
    }
    p += "plot ";
    for (std::size_t i = 0; i < clauses.size(); ++i) p += (i > 0 ? ", \\\n     " : "") + clauses[i];
    p += "\n";
    return f;
  }
};

constexpr const char* kDrawnIterationsTitle = "iterations shown in time";

std::string iteration_look(int position, double width) {
  return " linewidth " + gp_number(width) + " linecolor rgb '" + iteration_colour(position) + "' dashtype " +
         std::to_string(iteration_dash(position));
}

const IterationData& iteration_of(const Session& session, int iteration, const char* what) {
  if (iteration < 0 || iteration >= static_cast<int>(session.iterations.size())) {
    throw InputError(std::string(what) + " " + std::to_string(iteration) + ": the session has iterations 0 to " +
                     std::to_string(static_cast<int>(session.iterations.size()) - 1));
  }
  const IterationData& data = session.iterations[static_cast<std::size_t>(iteration)];
  if (data.record.learning_samples == 0)
    throw std::logic_error("figures: iteration " + std::to_string(iteration) + " was not loaded");
  return data;
}

/// The data the iteration figures share: per chosen iteration, the columns of `$iteration_J`
/// (time_s, angle_deg, u_ilc_bar, error_deg), kept for the layouts' point lists.
struct IterationColumns {
  int iteration = 0;
  Eigen::VectorXd time_s, angle_deg, u_ilc_bar, error_deg;
};

std::vector<IterationColumns> iteration_columns(const Session& session, const std::vector<int>& iterations) {
  std::vector<IterationColumns> out;
  for (int j : iterations) {
    const TrialRecord& record = iteration_of(session, j, "iteration").record;
    const TrialSamples& s = record.joint_samples(0);
    out.push_back(
        {j, rounded_times(record.sample_time_s), degrees_of(s.angle_rad), s.u_ilc_bar, degrees_of(s.error_rad)});
  }
  return out;
}

std::string iteration_blocks(const std::vector<IterationColumns>& columns) {
  std::string out;
  for (const IterationColumns& c : columns) {
    out +=
        data_block("iteration_" + std::to_string(c.iteration), {&c.time_s, &c.angle_deg, &c.u_ilc_bar, &c.error_deg});
  }
  return out;
}

AxisRange time_range(const Session& session) { return {0.0, session.trajectory.duration_s()}; }

Figure rms_figure(const Session& session, const FigureRequest& request, const FigureStyle& style,
                  const std::vector<int>& chosen) {
  const auto n = static_cast<Eigen::Index>(session.manifest.iterations.size());
  Eigen::VectorXd iteration(n), rms(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    iteration(i) = session.manifest.iterations[static_cast<std::size_t>(i)].summary.iteration;
    rms(i) = session.manifest.iterations[static_cast<std::size_t>(i)].summary.rms_deg;
  }
  // The drawn iterations, marked on the curve in their colours (one colour per iteration everywhere).
  const auto m = static_cast<Eigen::Index>(chosen.size());
  Eigen::VectorXd chosen_iteration(m), chosen_rms(m), chosen_colour(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const int j = chosen[static_cast<std::size_t>(i)];
    chosen_iteration(i) = j;
    chosen_rms(i) = session.manifest.iterations[static_cast<std::size_t>(j)].summary.rms_deg;
    chosen_colour(i) = static_cast<double>(std::stoi(iteration_colour(static_cast<int>(i)).substr(1), nullptr, 16));
  }
  std::string data =
      data_block("rms", {&iteration, &rms}) + data_block("rms_drawn", {&chosen_iteration, &chosen_rms, &chosen_colour});
  const std::string name = style.titles ? "bellows: " + session.manifest.name : "bellows";
  FigureBuilder b{style,
                  "RMS tracking error per iteration",
                  "iteration",
                  "RMS error [deg]",
                  {-0.4, static_cast<double>(n - 1) + 0.4},
                  true,
                  {},
                  {},
                  {}};
  if (n <= 16) b.extra = "set xtics 1\n";
  b.add({"$rms using 1:2 with linespoints linewidth 1.5 linecolor rgb '#000000' pointtype 7 pointsize 0.5",
         name,
         {&iteration, &rms}});
  Eigen::VectorXd paper_x, paper_y;
  if (request.paper_rms && !request.paper_rms->empty()) {
    const auto p = static_cast<Eigen::Index>(request.paper_rms->size());
    paper_x.resize(p), paper_y.resize(p);
    for (Eigen::Index i = 0; i < p; ++i) {
      paper_x(i) = (*request.paper_rms)[static_cast<std::size_t>(i)].first;
      paper_y(i) = (*request.paper_rms)[static_cast<std::size_t>(i)].second;
    }
    data += data_block("paper", {&paper_x, &paper_y});
    b.add(
        {"$paper using 1:2 with linespoints linewidth 1.5 linecolor rgb '#777777' dashtype 2 pointtype 6 pointsize 0.6",
         "paper",
         {&paper_x, &paper_y}});
  }
  b.add({"keyentry with points pointtype 7 pointsize 1.1 linecolor rgb '#777777'", kDrawnIterationsTitle, {}});
  b.add(
      {"$rms_drawn using 1:2:3 with points pointtype 7 pointsize 1.1 linecolor rgb variable", "", {}});  // last: on top
  return b.build("rms", std::move(data));
}

Figure angle_figure(const Session& session, const std::vector<IterationColumns>& columns, const FigureStyle& style) {
  const Trajectory& trajectory = session.trajectory;
  Eigen::VectorXd time_s(trajectory.learning_samples() + 1);
  for (Eigen::Index k = 0; k < time_s.size(); ++k) time_s(k) = static_cast<double>(k) * trajectory.sample_time_s;
  const Eigen::VectorXd times = rounded_times(time_s), angle = degrees_of(trajectory.joint(0));
  FigureBuilder b{style,
                  "Joint angle and set point: " + session.manifest.name,
                  "time [s]",
                  "angle θ [deg]",
                  time_range(session),
                  false,
                  {},
                  {},
                  {}};
  b.add({"$setpoint using 1:2 with lines linewidth 1.2 linecolor rgb '#000000' dashtype 2",
         "set point",
         {&times, &angle}},
        true);
  for (std::size_t i = 0; i < columns.size(); ++i) {
    const IterationColumns& c = columns[i];
    b.add({"$iteration_" + std::to_string(c.iteration) + " using 1:2 with lines" +
               iteration_look(static_cast<int>(i), 1.5),
           "iteration " + std::to_string(c.iteration),
           {&c.time_s, &c.angle_deg}});
  }
  return b.build("angle", data_block("setpoint", {&times, &angle}) + iteration_blocks(columns));
}

Figure error_figure(const Session& session, const std::vector<IterationColumns>& columns, const FigureStyle& style) {
  FigureBuilder b{style,
                  "Tracking error: " + session.manifest.name,
                  "time [s]",
                  "error e = r − θ [deg]",
                  time_range(session),
                  false,
                  "set xzeroaxis linetype 1 linecolor rgb '#777777' linewidth 0.8\n",
                  {},
                  {}};
  for (std::size_t i = 0; i < columns.size(); ++i) {
    const IterationColumns& c = columns[i];
    b.add({"$iteration_" + std::to_string(c.iteration) + " using 1:4 with lines" +
               iteration_look(static_cast<int>(i), 1.5),
           "iteration " + std::to_string(c.iteration),
           {&c.time_s, &c.error_deg}});
  }
  return b.build("error", {});  // reuses the angle figure's $iteration_J blocks
}

Figure correction_figure(const Session& session, const std::vector<IterationColumns>& columns,
                         const FigureStyle& style) {
  FigureBuilder b{style,
                  "Learned correction u_ilc: " + session.manifest.name,
                  "time [s]",
                  "ILC correction u_{ILC} [bar]",
                  time_range(session),
                  false,
                  "set xzeroaxis linetype 1 linecolor rgb '#777777' linewidth 0.8\n",
                  {},
                  {}};
  for (std::size_t i = 0; i < columns.size(); ++i) {
    const IterationColumns& c = columns[i];
    b.add({"$iteration_" + std::to_string(c.iteration) + " using 1:3 with steps" +
               iteration_look(static_cast<int>(i), 1.5),
           "iteration " + std::to_string(c.iteration),
           {&c.time_s, &c.u_ilc_bar}});
  }
  return b.build("u_ilc", {});  // reuses the angle figure's $iteration_J blocks
}

Figure pressure_figure(const Session& session, int trial, const FigureStyle& style) {
  const TrialRecord& record = iteration_of(session, trial, "trial").record;
  const TrialTicks& t = record.joint_ticks(0);
  const Eigen::VectorXd& supply_bar = record.supply_bar;
  const Eigen::VectorXd time_s = rounded_times(record.tick_time_s);
  std::string data = data_block(
      "pressures", {&time_s, &t.pressure_a_bar, &t.pressure_b_bar, &t.setpoint_a_bar, &t.setpoint_b_bar, &supply_bar});
  FigureBuilder b{style,
                  "Pressures, iteration " + std::to_string(trial) + ": " + session.manifest.name,
                  "time [s]",
                  "pressure [bar abs]",
                  time_range(session),
                  false,
                  {},
                  {},
                  {}};
  b.add({"$pressures using 1:2 with lines linewidth 1.5 linecolor rgb '" + std::string(kChamberAColour) + "'",
         "A measured",
         {&time_s, &t.pressure_a_bar}});
  b.add(
      {"$pressures using 1:4 with steps linewidth 0.8 linecolor rgb '" + std::string(kChamberAColour) + "' dashtype 2",
       "A set point",
       {&time_s, &t.setpoint_a_bar}},
      true);
  b.add({"$pressures using 1:3 with lines linewidth 1.5 linecolor rgb '" + std::string(kChamberBColour) + "'",
         "B measured",
         {&time_s, &t.pressure_b_bar}});
  b.add(
      {"$pressures using 1:5 with steps linewidth 0.8 linecolor rgb '" + std::string(kChamberBColour) + "' dashtype 2",
       "B set point",
       {&time_s, &t.setpoint_b_bar}},
      true);
  // The supply (3 bar on the paper's rig) squeezed the chambers into the bottom of the axis: drawn
  // only when it is near their range, else named in the legend's title.
  const double low = std::min(t.pressure_a_bar.minCoeff(), t.pressure_b_bar.minCoeff());
  const double high = std::max({t.pressure_a_bar.maxCoeff(), t.pressure_b_bar.maxCoeff(), t.setpoint_a_bar.maxCoeff(),
                                t.setpoint_b_bar.maxCoeff()});
  const double supply = supply_bar.size() > 0 ? supply_bar.mean() : 0.0;
  if (supply <= high + 0.25 * (high - low)) {
    b.add({"$pressures using 1:6 with lines linewidth 1 linecolor rgb '#999999' dashtype 3",
           "supply",
           {&time_s, &supply_bar}});
    b.legend_heading = "chambers";
  } else {
    char heading[64];
    std::snprintf(heading, sizeof heading, "chambers (supply %.2f bar abs)", supply);
    b.legend_heading = heading;
  }
  return b.build("pressures", std::move(data));
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

std::vector<int> figure_iterations(const FigureRequest& request, int count) {
  std::vector<int> out = request.iterations.empty() ? default_plot_iterations(count) : request.iterations;
  out.push_back(request.pressure_trial < 0 ? count - 1 : request.pressure_trial);
  return out;
}

std::vector<Figure> session_figures(const Session& session, const FigureRequest& request) {
  for (const std::string& format : request.formats) figure_terminal(figure_style("screen"), format);
  const FigureStyle style = figure_style(request.style);
  const int count = static_cast<int>(session.iterations.size());
  if (count == 0) throw InputError("session " + session.directory.string() + " has no iteration to plot");
  std::vector<int> iterations = request.iterations.empty() ? default_plot_iterations(count) : request.iterations;
  const std::vector<IterationColumns> columns = iteration_columns(session, iterations);  // checks them
  const int trial = request.pressure_trial < 0 ? count - 1 : request.pressure_trial;
  return {rms_figure(session, request, style, iterations), angle_figure(session, columns, style),
          error_figure(session, columns, style), correction_figure(session, columns, style),
          pressure_figure(session, trial, style)};
}

std::vector<fs::path> figure_files(const std::vector<Figure>& figures, const std::vector<std::string>& formats,
                                   const fs::path& directory) {
  std::vector<fs::path> out;
  for (const Figure& figure : figures) {
    for (const std::string& format : formats) out.push_back(directory / (figure.name + "." + format));
  }
  return out;
}

std::string gnuplot_script(const std::vector<Figure>& figures, const std::vector<std::string>& formats,
                           const std::string& style_name) {
  const FigureStyle style = figure_style(style_name);
  std::string out = "# Written by bellows sessions plot (style " + style.name +
                    "); `gnuplot figures.gp` in this folder draws them again.\nset encoding utf8\n";
  for (const Figure& figure : figures) out += figure.data;
  for (const Figure& figure : figures) {
    for (const std::string& format : formats) {
      out += "\n# " + figure.name + "." + format + "\nreset\n" + figure_terminal(style, format) + "\nset output " +
             gp_quoted(figure.name + "." + format) + "\n" + figure.plot + "unset output\n";
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
