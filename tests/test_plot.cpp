// `bellows sessions plot`: the generated gnuplot script holds the expected series and data, gnuplot
// draws every figure in every format and style (non-empty files; the SVGs name the series), the
// paper's curve is overlaid when given, one colour per iteration in every figure, ranges fitted to
// the data, legends inside the axes, and bad requests and existing files are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "app/plot_command.hpp"
#include "app/plot_figures.hpp"
#include "app/plot_style.hpp"
#include "engine/base/errors.hpp"
#include "tests/session_export_fixture.hpp"

namespace bellows {
namespace {

namespace fs = std::filesystem;
using testing::ProcessResult;
using testing::run_bellows;
using testing::TempDir;

class Plot : public ::testing::Test {
 protected:
  void SetUp() override { session_ = testing::saved_faulted_session(dir_ / "s", 4); }
  TempDir dir_;
  Session session_;
};

const Figure& named(const std::vector<Figure>& figures, const std::string& name) {
  for (const Figure& figure : figures) {
    if (figure.name == name) return figure;
  }
  throw std::runtime_error("no figure " + name);
}

TEST_F(Plot, TheFiguresHaveTheExpectedSeriesAndData) {
  FigureRequest request;
  request.iterations = {0, 3};
  request.pressure_trial = 2;
  request.paper_rms = std::vector<std::pair<double, double>>{{0, 12.6}, {1, 9.5}};
  const std::vector<Figure> figures = session_figures(session_, request);
  ASSERT_EQ(figures.size(), 5u);
  EXPECT_EQ(named(figures, "rms").series,
            (std::vector<std::string>{"bellows: s", "paper", "iterations shown in time"}));
  EXPECT_EQ(named(figures, "angle").series, (std::vector<std::string>{"set point", "iteration 0", "iteration 3"}));
  EXPECT_EQ(named(figures, "error").series, (std::vector<std::string>{"iteration 0", "iteration 3"}));
  EXPECT_EQ(named(figures, "u_ilc").series, (std::vector<std::string>{"iteration 0", "iteration 3"}));
  EXPECT_EQ(named(figures, "pressures").series,
            (std::vector<std::string>{"A measured", "A set point", "B measured", "B set point"}));
  // The supply, far above the chambers' pressures, is named in the legend's title, not drawn.
  EXPECT_NE(named(figures, "pressures").plot.find("title 'chambers (supply "), std::string::npos)
      << named(figures, "pressures").plot;
  EXPECT_NE(named(figures, "rms").plot.find("set logscale y"), std::string::npos);
  EXPECT_NE(named(figures, "pressures").plot.find("Pressures, iteration 2"), std::string::npos);
  // The RMS data block holds the manifest's values, one row per iteration.
  const std::string& rms = named(figures, "rms").data;
  for (const IterationEntry& entry : session_.manifest.iterations) {
    char row[64];
    std::snprintf(row, sizeof row, "\n%d %.17g", entry.summary.iteration, entry.summary.rms_deg);
    const std::string shortest = std::to_string(entry.summary.iteration) + " ";
    EXPECT_NE(rms.find("\n" + shortest), std::string::npos) << rms;
  }
  EXPECT_NE(rms.find("$paper << EOD\n0 12.6\n1 9.5\nEOD\n"), std::string::npos) << rms;
  // The last iteration's u_ilc values are in its block (third column).
  const std::string& data = named(figures, "angle").data;
  EXPECT_NE(data.find("$iteration_3 << EOD\n"), std::string::npos);
  EXPECT_EQ(data.find("$iteration_1 << EOD\n"), std::string::npos);
  const std::string script = gnuplot_script(figures, {"png", "svg"});
  EXPECT_NE(script.find("set output 'rms.png'"), std::string::npos);
  EXPECT_NE(script.find("set output 'pressures.svg'"), std::string::npos);
}

TEST_F(Plot, DefaultsToFirstSecondMiddleAndLastIteration) {
  EXPECT_EQ(default_plot_iterations(1), (std::vector<int>{0}));
  EXPECT_EQ(default_plot_iterations(2), (std::vector<int>{0, 1}));
  EXPECT_EQ(default_plot_iterations(31), (std::vector<int>{0, 1, 15, 30}));
  const std::vector<Figure> figures = session_figures(session_, FigureRequest{});
  EXPECT_EQ(named(figures, "u_ilc").series,
            (std::vector<std::string>{"iteration 0", "iteration 1", "iteration 2", "iteration 3"}));
  EXPECT_EQ(named(figures, "rms").series,
            (std::vector<std::string>{"bellows: s", "iterations shown in time"}));  // no overlay unless asked
}

TEST_F(Plot, RefusesIterationsAndFormatsTheSessionCannotGive) {
  FigureRequest request;
  request.iterations = {0, 9};
  EXPECT_THROW(session_figures(session_, request), InputError);
  request.iterations = {};
  request.pressure_trial = 4;
  EXPECT_THROW(session_figures(session_, request), InputError);
  request.pressure_trial = -1;
  request.formats = {"gif"};
  EXPECT_THROW(session_figures(session_, request), InputError);
}

TEST_F(Plot, GnuplotDrawsEveryFigureInEveryFormat) {
  testing::write_text(dir_ / "paper.csv", "iteration,rms_deg\n0,12.6\n1,9.5\n2,7.4\n");
  const ProcessResult result =
      run_bellows({"sessions", "plot", (dir_ / "s").string(), "--output", (dir_ / "figs").string(), "--formats",
                   "png,svg,pdf", "--paper", (dir_ / "paper.csv").string(), "--iterations", "0,3", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json report = nlohmann::json::parse(result.out);
  EXPECT_EQ(report["files"].size(), 1u + 5u * 3u);  // the script, then 5 figures x 3 formats
  EXPECT_EQ(report["style"], "screen");
  for (const std::string name : {"rms", "angle", "error", "u_ilc", "pressures"}) {
    for (const std::string format : {"png", "svg", "pdf"}) {
      const fs::path file = dir_ / "figs" / (name + "." + format);
      ASSERT_TRUE(fs::exists(file)) << file;
      EXPECT_GT(fs::file_size(file), 1000u) << file;
    }
  }
  EXPECT_EQ(testing::read_text(dir_ / "figs" / "rms.png").substr(1, 3), "PNG");
  EXPECT_EQ(testing::read_text(dir_ / "figs" / "rms.pdf").substr(0, 5), "%PDF-");
  const std::string rms = testing::read_text(dir_ / "figs" / "rms.svg");
  EXPECT_NE(rms.find(">bellows: s<"), std::string::npos);
  EXPECT_NE(rms.find(">paper<"), std::string::npos);
  const std::string angle = testing::read_text(dir_ / "figs" / "angle.svg");
  for (const std::string series : {">set point<", ">iteration 0<", ">iteration 3<"}) {
    EXPECT_NE(angle.find(series), std::string::npos) << series;
  }
  const std::string pressures = testing::read_text(dir_ / "figs" / "pressures.svg");
  EXPECT_NE(pressures.find(">A measured<"), std::string::npos);
  EXPECT_NE(pressures.find(">B set point<"), std::string::npos);
  EXPECT_NE(pressures.find(">chambers (supply "), std::string::npos);
  const std::string error = testing::read_text(dir_ / "figs" / "error.svg");
  EXPECT_NE(error.find(">iteration 3<"), std::string::npos);

  // Again: the figures exist, so nothing is replaced without --force.
  const ProcessResult again =
      run_bellows({"sessions", "plot", (dir_ / "s").string(), "--output", (dir_ / "figs").string()});
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_EQ(again.err,
            "bellows: " + (dir_ / "figs" / "figures.gp").string() + " exists already (--force replaces it)\n");
  const ProcessResult forced =
      run_bellows({"sessions", "plot", (dir_ / "s").string(), "--output", (dir_ / "figs").string(), "--force"});
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
}

TEST_F(Plot, OneLineForABadRequest) {
  for (const std::vector<std::string>& args : {std::vector<std::string>{"--iterations", "0,12"},
                                               {"--trial", "7"},
                                               {"--output", (dir_ / "s" / "figs").string()},
                                               {"--output", (dir_ / "no" / "figs").string()},
                                               {"--paper", (dir_ / "missing.csv").string()},
                                               {"--formats", "gif"},
                                               {"--style", "poster"},
                                               {"--paper", (dir_ / "s" / "manifest.json").string()}}) {
    std::vector<std::string> command = {"sessions", "plot", (dir_ / "s").string()};
    command.insert(command.end(), args.begin(), args.end());
    const ProcessResult result = run_bellows(command);
    EXPECT_EQ(result.exit_code, 2) << args[0] << " " << args[1];
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "s" / "figs"));
}

/// The text of `figure`'s plot command: from "plot " to its end.
std::string plot_command_of(const Figure& figure) { return figure.plot.substr(figure.plot.find("\nplot ") + 1); }

/// The colour of the curve drawing `block` (e.g. "$iteration_0 using 1:2") in `figure`.
std::string colour_of(const Figure& figure, const std::string& block) {
  const std::string plot = plot_command_of(figure);
  const std::size_t at = plot.rfind(block);  // the curve itself (a keyentry comes first)
  const std::size_t colour = plot.find("rgb '", at);
  return at == std::string::npos || colour == std::string::npos ? "" : plot.substr(colour + 5, 7);
}

TEST_F(Plot, OneColourPerIterationInEveryFigureAndTheSetPointOnTop) {
  FigureRequest request;
  request.iterations = {0, 2, 3};
  const std::vector<Figure> figures = session_figures(session_, request);
  std::set<std::string> colours;
  for (int j : {0, 2, 3}) {
    const std::string block = "$iteration_" + std::to_string(j) + " using ";
    const std::string colour = colour_of(named(figures, "angle"), block);
    ASSERT_EQ(colour.size(), 7u) << j;
    EXPECT_EQ(colour_of(named(figures, "error"), block), colour) << j;
    EXPECT_EQ(colour_of(named(figures, "u_ilc"), block), colour) << j;
    colours.insert(colour);
  }
  EXPECT_EQ(colours.size(), 3u);  // three iterations, three colours
  // Iteration 0 has the first colour whatever else is drawn; its RMS mark has it too.
  FigureRequest other;
  other.iterations = {0, 1};
  EXPECT_EQ(colour_of(named(session_figures(session_, other), "angle"), "$iteration_0 using "), iteration_colour(0));
  EXPECT_EQ(colour_of(named(figures, "angle"), "$iteration_0 using "), iteration_colour(0));
  EXPECT_NE(named(figures, "rms").data.find("\n0 "), std::string::npos);
  const std::string marks = named(figures, "rms").data.substr(named(figures, "rms").data.find("$rms_drawn"));
  EXPECT_NE(marks.find(" " + std::to_string(std::stoi(iteration_colour(0).substr(1), nullptr, 16)) + "\n"),
            std::string::npos)
      << marks;
  // Enough contrast on white: no palette colour is lighter than 3:1 (WCAG's floor for graphics).
  for (int i = 0; i < iteration_colours(); ++i) {
    const int rgb = std::stoi(iteration_colour(i).substr(1), nullptr, 16);
    double luminance = 0.0;
    const double weights[] = {0.2126, 0.7152, 0.0722};
    for (int c = 0; c < 3; ++c) {
      const double v = ((rgb >> (16 - 8 * c)) & 0xff) / 255.0;
      luminance += weights[c] * (v <= 0.03928 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
    }
    EXPECT_GE(1.05 / (luminance + 0.05), 3.0) << iteration_colour(i);
  }
  // The set point is drawn after every iteration (on top), yet first in the legend.
  const std::string angle = plot_command_of(named(figures, "angle"));
  EXPECT_GT(angle.rfind("$setpoint using"), angle.rfind("$iteration_3 using")) << angle;
  EXPECT_LT(angle.find("keyentry"), angle.find("$iteration_0")) << angle;
}

/// The numbers of `set <axis>range [low:high]` in `plot`.
std::pair<double, double> range_of(const std::string& plot, const std::string& axis) {
  const std::size_t at = plot.find("set " + axis + "range [");
  if (at == std::string::npos) return {NAN, NAN};
  const std::size_t open = at + axis.size() + 11;
  const std::size_t colon = plot.find(':', open);
  return {std::stod(plot.substr(open, colon - open)), std::stod(plot.substr(colon + 1))};
}

TEST_F(Plot, RangesFitTheDataAndLegendsSitInsideTheAxes) {
  const std::vector<Figure> figures = session_figures(session_, FigureRequest{});
  double low = 1e9, high = 0.0;
  for (const IterationEntry& e : session_.manifest.iterations)
    low = std::min(low, e.summary.rms_deg), high = std::max(high, e.summary.rms_deg);
  const auto [rms_low, rms_high] = range_of(named(figures, "rms").plot, "y");
  EXPECT_LE(rms_low, low);
  EXPECT_GT(rms_low, low * 0.8) << "not a decade below the data";
  EXPECT_GE(rms_high, high);
  EXPECT_LT(rms_high, high * 2.0) << "not a decade above the data";
  EXPECT_NE(named(figures, "rms").plot.find("set ytics ("), std::string::npos);  // labelled ticks inside the range
  // Pressures: the axis spans the chambers, not the supply far above them.
  const TrialTicks& t = session_.iterations.back().record.joint_ticks(0);
  const double p_low = std::min(t.pressure_a_bar.minCoeff(), t.pressure_b_bar.minCoeff());
  const double p_high = std::max({t.pressure_a_bar.maxCoeff(), t.pressure_b_bar.maxCoeff(), t.setpoint_a_bar.maxCoeff(),
                                  t.setpoint_b_bar.maxCoeff()});
  const auto [y_low, y_high] = range_of(named(figures, "pressures").plot, "y");
  EXPECT_LE(y_low, p_low);
  EXPECT_GE(y_high, p_high);
  EXPECT_LT(y_high - y_low, 2.0 * (p_high - p_low)) << "the data fill at least half the axis";
  // Time axes end where the trial does.
  EXPECT_DOUBLE_EQ(range_of(named(figures, "angle").plot, "x").second, session_.trajectory.duration_s());
  for (const Figure& f : figures) {
    EXPECT_NE(f.plot.find("set key inside"), std::string::npos) << f.name;
    EXPECT_EQ(f.plot.find("outside"), std::string::npos) << f.name;
  }
}

TEST_F(Plot, PaperStylesHaveThePapersSizesAndNoTitles) {
  EXPECT_THROW(figure_style("poster"), InputError);
  const FigureStyle column = figure_style("paper-column");
  EXPECT_EQ(figure_terminal(column, "pdf").find("set terminal pdfcairo size 3.5in,2.45in"), 0u)
      << figure_terminal(column, "pdf");
  EXPECT_EQ(figure_terminal(column, "png").find("set terminal pngcairo size 1050,735"), 0u)
      << figure_terminal(column, "png");
  EXPECT_EQ(figure_terminal(figure_style("paper-wide"), "pdf").find("set terminal pdfcairo size 7.16in,"), 0u);
  EXPECT_NE(figure_terminal(figure_style("screen"), "svg").find("set terminal svg size 720,450"), std::string::npos);
  FigureRequest request;
  request.style = "paper-column";
  const std::vector<Figure> figures = session_figures(session_, request);
  for (const Figure& f : figures)
    EXPECT_EQ(f.plot.find("set title"), std::string::npos) << f.name;  // the caption's job
  EXPECT_NE(gnuplot_script(figures, {"pdf"}, "paper-column").find("pdfcairo size 3.5in"), std::string::npos);
  EXPECT_NE(session_figures(session_, FigureRequest{})[1].plot.find("set title"), std::string::npos);  // screen: titled
}

TEST_F(Plot, ThePapersCurveIsNamedOrItsAbsenceSaid) {
  FigureRequest request;
  EXPECT_TRUE(add_paper_curve(request, "steps", {}, false).note.empty());  // not the paper's trajectory
  EXPECT_FALSE(request.paper_rms);
  testing::write_text(dir_ / "paper.csv", "iteration,rms_deg\n0,12.6\n1,9.5\n");
  const PaperCurve given = add_paper_curve(request, "steps", (dir_ / "paper.csv").string(), false);
  EXPECT_EQ(given.note, "paper's RMS curve from " + (dir_ / "paper.csv").string());
  ASSERT_TRUE(request.paper_rms);
  EXPECT_EQ(request.paper_rms->size(), 2u);
  FigureRequest none;
  EXPECT_TRUE(add_paper_curve(none, "paper", {}, true).note.empty());
  EXPECT_THROW(add_paper_curve(none, "paper", (dir_ / "paper.csv").string(), true), InputError);
  const PaperCurve found = add_paper_curve(none, "paper", {}, false);
  if (fs::is_regular_file(default_paper_rms_path())) {
    EXPECT_EQ(found.note, "paper's RMS curve from " + default_paper_rms_path().string());
  } else {
    EXPECT_EQ(found.note, "paper's RMS curve: not overlaid, " + default_paper_rms_path().string() +
                              " is not there (--paper FILE gives one)");
    EXPECT_FALSE(none.paper_rms);
  }
}

TEST_F(Plot, AFewIterationsOfALongSessionAreRead) {
  FigureRequest request;
  request.iterations = {1};
  const Session part = read_figure_session(dir_ / "s", request);
  ASSERT_EQ(part.iterations.size(), 4u);
  EXPECT_EQ(part.manifest.iterations.size(), 4u);
  EXPECT_EQ(part.iterations[0].record.learning_samples, 0);  // not read
  EXPECT_GT(part.iterations[1].record.learning_samples, 0);
  EXPECT_GT(part.iterations[3].record.learning_samples, 0);  // the pressures' trial
  EXPECT_EQ(session_figures(part, request).size(), 5u);
  const Session first_two = read_figure_session(dir_ / "s", FigureRequest{}, 2);
  EXPECT_EQ(first_two.manifest.iterations.size(), 2u);
  EXPECT_NE(named(session_figures(first_two, FigureRequest{}), "pressures").plot.find("Pressures, iteration 1:"),
            std::string::npos);
}

TEST(PlotPaper, TheSharedCurveIsReadWhenPresent) {
  const fs::path shared = fs::path(BELLOWS_SHARED_DIR) / "data" / "paper_rms.csv";
  if (!fs::exists(shared)) GTEST_SKIP() << "no " << shared << " beside the source tree";
  const auto paper = read_paper_rms(shared);
  ASSERT_GT(paper.size(), 10u);
  EXPECT_EQ(paper.front().first, 0.0);
  EXPECT_NEAR(paper.front().second, 12.6, 0.05);
  EXPECT_EQ(default_paper_rms_path().filename(), "paper_rms.csv");
}

}  // namespace
}  // namespace bellows
