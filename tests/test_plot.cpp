// `bellows sessions plot`: the generated gnuplot script holds the expected series and data, gnuplot
// draws every figure in every format (non-empty files; the SVGs name the series), the paper's curve
// is overlaid when given, and bad requests and existing files are refused.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "app/plot_command.hpp"
#include "app/plot_figures.hpp"
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
  ASSERT_EQ(figures.size(), 4u);
  EXPECT_EQ(named(figures, "rms").series, (std::vector<std::string>{"bellows: s", "paper"}));
  EXPECT_EQ(named(figures, "angle").series, (std::vector<std::string>{"set point", "iteration 0", "iteration 3"}));
  EXPECT_EQ(named(figures, "u_ilc").series, (std::vector<std::string>{"iteration 0", "iteration 3"}));
  EXPECT_EQ(named(figures, "pressures").series.size(), 5u);
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
  EXPECT_EQ(named(figures, "u_ilc").series, (std::vector<std::string>{"iteration 0", "iteration 1", "iteration 2", "iteration 3"}));
  EXPECT_EQ(named(figures, "rms").series, (std::vector<std::string>{"bellows: s"}));  // no overlay unless asked
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
  const ProcessResult result = run_bellows({"sessions", "plot", (dir_ / "s").string(), "--output", (dir_ / "figs").string(),
                                            "--formats", "png,svg,pdf", "--paper", (dir_ / "paper.csv").string(),
                                            "--iterations", "0,3", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json report = nlohmann::json::parse(result.out);
  EXPECT_EQ(report["files"].size(), 1u + 4u * 3u);  // the script, then 4 figures x 3 formats
  for (const std::string name : {"rms", "angle", "u_ilc", "pressures"}) {
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
  EXPECT_NE(pressures.find(">p_A measured<"), std::string::npos);
  EXPECT_NE(pressures.find(">supply<"), std::string::npos);

  // Again: the figures exist, so nothing is replaced without --force.
  const ProcessResult again = run_bellows({"sessions", "plot", (dir_ / "s").string(), "--output", (dir_ / "figs").string()});
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_EQ(again.err, "bellows: " + (dir_ / "figs" / "figures.gp").string() + " exists already (--force replaces it)\n");
  const ProcessResult forced =
      run_bellows({"sessions", "plot", (dir_ / "s").string(), "--output", (dir_ / "figs").string(), "--force"});
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
}

TEST_F(Plot, OneLineForABadRequest) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--iterations", "0,12"}, {"--trial", "7"}, {"--output", (dir_ / "s" / "figs").string()},
        {"--output", (dir_ / "no" / "figs").string()}, {"--paper", (dir_ / "missing.csv").string()},
        {"--formats", "gif"}}) {
    std::vector<std::string> command = {"sessions", "plot", (dir_ / "s").string()};
    command.insert(command.end(), args.begin(), args.end());
    const ProcessResult result = run_bellows(command);
    EXPECT_EQ(result.exit_code, 2) << args[0] << " " << args[1];
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "s" / "figs"));
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
