// The learning laws behind `[ilc] law`: the factory, each law's frequency response (what the
// convergence prediction relies on) against its actual update, the zero-phase Q-filter, and
// learning on the paper scenario with the simulated arm.
#include <cmath>
#include <numbers>
#include <utility>

#include <gtest/gtest.h>

#include "devices/simulated_arm.hpp"
#include "engine/base/errors.hpp"
#include "engine/config/learning_law_factory.hpp"
#include "engine/rt/engine_core.hpp"
#include "engine/operator/learning_session.hpp"
#include "engine/learning/zero_phase_filter.hpp"
#include "tests/learning_curve.hpp"
#include "tests/test_support.hpp"

namespace bellows {
namespace {

using testing::paper_model;

std::unique_ptr<LearningLaw> make(const std::string& name, int samples, Configuration config = {}) {
  config.ilc.law = name;
  return make_learning_law(config, paper_model(), samples);
}

TEST(LearningLaws, FactoryBuildsEveryNamedLawAndNoilcIsTheDefault) {
  EXPECT_EQ(Configuration{}.ilc.law, "noilc");
  for (const std::string& name : learning_law_names()) {
    const auto law = make(name, 50);
    EXPECT_EQ(law->name(), name);
    EXPECT_EQ(law->samples(), 50);
    EXPECT_FALSE(learning_law_description(name).empty());
  }
  EXPECT_EQ(learning_law_names().size(), 7u);
}

TEST(LearningLaws, FactoryRejectsUnknownNamesAndBadParametersNamingTheKey) {
  try {
    make("p-type", 50);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("noilc-constrained"), std::string::npos) << error.what();
  }
  Configuration config;
  config.ilc.gradient_step = 2.5;
  EXPECT_THROW(make("gradient", 50, config), InputError);
  config = {};
  config.ilc.pd_q_cutoff_hz = 30.0;  // above Nyquist at 50 Hz
  EXPECT_THROW(make("pd", 50, config), InputError);
  config = {};
  config.ilc.inverse_gain = 1.5;
  try {
    make("inverse", 50, config);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("[ilc] inverse_gain"), std::string::npos) << error.what();
  }
}

// In the middle of a long trial a law acts on an everlasting sinusoid as its frequency response says:
// u_next = Re(Lu e^{i theta t}) for u_j = cos(theta t), e_j = 0, and Re(Le e^{i theta t}) for the error.
TEST(LearningLaws, FrequencyResponseMatchesTheUpdateAwayFromTheTrialEnds) {
  constexpr int kSamples = 1200;
  for (const std::string& name : learning_law_names()) {
    const auto law = make(name, kSamples);
    if (name == "noilc-learned") {  // its model changes with the trials: not linear and time-invariant
      EXPECT_FALSE(law->frequency_response(0.3).has_value());
      continue;
    }
    for (double theta : {0.05, 0.3, 1.0, 2.5}) {
      const auto response = law->frequency_response(theta);
      ASSERT_TRUE(response.has_value()) << name;
      Eigen::VectorXd wave(kSamples), zero = Eigen::VectorXd::Zero(kSamples), next(kSamples);
      for (int t = 0; t < kSamples; ++t) wave(t) = std::cos(theta * t);
      for (int input = 0; input < 2; ++input) {
        if (input == 0) law->update(wave, zero, next);
        else law->update(zero, wave, next);
        const std::complex<double> gain = input == 0 ? response->from_correction : response->from_error;
        double worst = 0.0;
        for (int t = kSamples / 2 - 50; t < kSamples / 2 + 50; ++t) {
          const double expected = (gain * std::polar(1.0, theta * t)).real();
          worst = std::max(worst, std::abs(next(t) - expected));
        }
        EXPECT_LT(worst, 1e-6 * (1.0 + std::abs(gain))) << name << " theta " << theta << " input " << input;
      }
    }
  }
}

TEST(ZeroPhaseLowPass, PassesConstantsWithoutDelayAndAttenuatesAsItsGainSays) {
  const ZeroPhaseLowPass filter(3.0, 0.02);
  EXPECT_NEAR(filter.gain(0.0), 1.0, 1e-12);
  EXPECT_NEAR(filter.gain(2.0 * std::numbers::pi * 3.0 * 0.02), 0.5, 1e-9);  // -3 dB per pass at the cutoff
  Eigen::VectorXd constant = Eigen::VectorXd::Constant(100, 0.3), out(100);
  filter.apply(constant, out);
  EXPECT_LT((out - constant).cwiseAbs().maxCoeff(), 1e-12);
  // A symmetric pulse stays symmetric about its centre: no phase shift.
  Eigen::VectorXd pulse = Eigen::VectorXd::Zero(201);
  pulse.segment(90, 21).setOnes();
  out.resize(201);
  filter.apply(pulse, out);
  for (int k = 0; k <= 100; ++k) EXPECT_NEAR(out(100 - k), out(100 + k), 1e-9);
  EXPECT_THROW(ZeroPhaseLowPass(25.0, 0.02), InputError);
  EXPECT_THROW(ZeroPhaseLowPass(0.0, 0.02), InputError);
}

// The paper scenario on the simulated arm, headless.
std::vector<double> learn_on_paper_scenario(const std::string& law_name, int iterations, Configuration config = {}) {
  return testing::learning_curve(std::move(config), law_name, "paper", iterations);
}

double floor_of(const std::vector<double>& rms, int last) {
  double sum = 0.0;
  for (int i = 0; i < last; ++i) sum += rms[rms.size() - 1 - i];
  return sum / last;
}

TEST(LearningLawsOnThePaperScenario, EveryLawLearnsAndPdSettlesAboveNormOptimal) {
  constexpr int kIterations = 60;
  const std::vector<double> noilc = learn_on_paper_scenario("noilc", kIterations);
  const std::vector<double> pd = learn_on_paper_scenario("pd", kIterations);
  const std::vector<double> gradient = learn_on_paper_scenario("gradient", kIterations);
  const std::vector<double> inverse = learn_on_paper_scenario("inverse", kIterations);
  EXPECT_GT(noilc[0], 10.0);  // feedback alone
  EXPECT_LT(noilc[30], 1.2);
  EXPECT_LT(floor_of(pd, 10), 2.5);
  EXPECT_LT(floor_of(gradient, 10), 1.5);
  EXPECT_LT(floor_of(inverse, 10), 1.2);
  // PD-type ILC with its (default, predicted-convergent) Q-filter stops at a worse floor than NOILC.
  EXPECT_GT(floor_of(pd, 10), 1.5 * floor_of(noilc, 10));
  // The O(N) form and the dense closed form learn identically on the arm (same seed, same optimum).
  const std::vector<double> dense = learn_on_paper_scenario("noilc-dense", 10);
  for (int i = 0; i <= 10; ++i) EXPECT_NEAR(dense[i], noilc[i], 1e-6) << "iteration " << i;
}

}  // namespace
}  // namespace bellows
