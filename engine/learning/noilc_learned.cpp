#include "engine/learning/noilc_learned.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/base/errors.hpp"

namespace bellows {
namespace {
// The guard halves the step after each trial that got worse, down to this: near the noise floor a
// trial can look worse by chance, and a vanishing step would stop learning for good.
constexpr double kSmallestStep = 0.125;
}  // namespace

LearnedModelNoilc::LearnedModelNoilc(const ClosedLoopPrior& prior, const LearnedNoilcSettings& settings, int samples)
    : prior_(prior), settings_(settings), samples_(samples) {
  if (!(settings.forgetting > 0.0) || settings.forgetting > 1.0)
    throw InputError("[ilc] learned_forgetting must be in (0, 1]");
  if (!(settings.relative_ridge > 0.0) || !std::isfinite(settings.relative_ridge))
    throw InputError("[ilc] learned_ridge must be positive");
  if (!(settings.guard >= 0.0) || !std::isfinite(settings.guard))
    throw InputError("[ilc] learned_guard must be a finite, non-negative fraction");
  if (settings.shape.taps < 0) throw InputError("[ilc] the correction's taps must not be negative");
  for (const double tau : settings.shape.lowpass_time_constants_s) {
    if (!(tau > 0.0) || !std::isfinite(tau)) throw InputError("[ilc] the correction's time constants must be positive");
  }
  const int J = prior.joints(), q = coefficients_per_output();
  correction_ = Eigen::MatrixXd::Zero(q, J);
  gram_.assign(static_cast<std::size_t>(J), Eigen::MatrixXd::Zero(q, q));
  moment_.assign(static_cast<std::size_t>(J), Eigen::VectorXd::Zero(q));
  regressors_.resize(samples, q);
  data_scale_ = Eigen::VectorXd::Zero(J);
  if (!(settings.limit_margin_bar >= 0.0) || !std::isfinite(settings.limit_margin_bar))
    throw InputError("[ilc] limit_margin_bar must be a finite, non-negative pressure");
  if (!(settings.limit_recovery_s >= 0.0) || !std::isfinite(settings.limit_recovery_s))
    throw InputError("[ilc] limit_recovery_s must be a finite, non-negative time");
  if (!(settings.joints_descent_slack >= 0.0) || settings.joints_descent_slack > settings.guard)
    throw InputError("[ilc] learned_joints_descent_slack must be between 0 and learned_guard");
  learnable_ = Eigen::MatrixXd::Ones(samples, J);
  feedback_ = Eigen::MatrixXd::Zero(samples, J);
  // The prior alone has no correction states (they would only add zeros to its predictions); the
  // refit model has them, and a refit rewrites its outputs only.
  prior_model_ = closed_loop_model(prior_, CorrectionShape{0, {}}, {});
  model_ = closed_loop_model(prior_, settings_.shape, correction_);
  prior_solver_.setup(prior_model_, settings_.weights, samples_);
  rebuild();
  plan_with_prior_ = prior_plans_always();
}

void LearnedModelNoilc::rebuild() {
  set_correction(settings_.shape, correction_, model_);
  solver_.setup(model_, settings_.weights, samples_);
}

void LearnedModelNoilc::set_input_context(const Eigen::Ref<const Eigen::MatrixXd>& feedback_bar,
                                          double input_limit_bar) {
  if (feedback_bar.rows() != samples_ || feedback_bar.cols() != joints()) {
    throw InputError("noilc-learned: the feedback is not " + std::to_string(samples_) + " x " +
                     std::to_string(joints()));
  }
  reach_bar_ = input_limit_bar - settings_.limit_margin_bar;
  if (!(reach_bar_ > 0.0)) throw InputError("[ilc] limit_margin_bar leaves no room below the pressure limit");
  feedback_ = feedback_bar;
  has_context_ = true;
}

void LearnedModelNoilc::set_held_outputs(const std::vector<unsigned char>& held) {
  // Sample k's output is error entry k - 1 (entries are samples 1..N).
  for (std::size_t k = 1; k < held.size() && static_cast<int>(k) <= samples_; ++k) {
    if (held[k] != 0) learnable_.row(static_cast<Eigen::Index>(k) - 1).setZero();
  }
}

void LearnedModelNoilc::refit(const Eigen::MatrixXd& du, const Eigen::MatrixXd& residual,
                              const Eigen::MatrixXd& learnable) {
  const double T = prior_.sample_time_s;
  const int p = settings_.shape.per_joint(), q = coefficients_per_output();
  const bool cross_joint = q != p;
  // Cross-joint: every output is fitted on the regressors of every joint's input (the coupling the
  // prior has wrong), [Phi(du_1) | ... | Phi(du_J)]; diagonal: on its own input's.
  if (cross_joint) {
    for (int k = 0; k < joints(); ++k)
      regressors_.middleCols(k * p, p) = correction_regressors(du.col(k), settings_.shape, T);
  }
  for (int i = 0; i < joints(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!cross_joint) regressors_ = correction_regressors(du.col(i), settings_.shape, T);
    // Rows the refit may not learn from (limit-shaped, held) are left out of the fit altogether. The
    // outputs of several joints usually share them: their product is then made once.
    if (!cross_joint || i == 0 || learnable.col(i) != learnable.col(i - 1)) {
      masked_ = learnable.col(i).asDiagonal() * regressors_;
      increment_.noalias() = masked_.transpose() * masked_;
      increment_scale_ = masked_.squaredNorm() / q;
    }
    const Eigen::VectorXd r = learnable.col(i).cwiseProduct(residual.col(i));
    gram_[k] *= settings_.forgetting;
    moment_[k] *= settings_.forgetting;
    gram_[k] += increment_;
    moment_[k].noalias() += masked_.transpose() * r;
    // The ridge pulls towards the prior (a zero correction) with a weight relative to the largest
    // change of correction seen: a trial whose correction barely changed (near convergence, the change
    // is below the noise) then adds almost nothing to the fit, and the model stays what the
    // informative trials made it instead of walking away with the noise.
    data_scale_(i) = std::max(data_scale_(i), increment_scale_);
    if (!(data_scale_(i) > 0.0)) continue;  // the correction never changed: nothing to learn from
    const double ridge = settings_.relative_ridge * data_scale_(i);
    Eigen::MatrixXd a = gram_[k];
    a.diagonal().array() += ridge;
    const Eigen::VectorXd theta = a.ldlt().solve(moment_[k]);
    if (theta.allFinite()) correction_.col(i) = theta;
  }
}

void LearnedModelNoilc::leave_out_limited_outputs(const Eigen::Ref<const Eigen::MatrixXd>& u_j) {
  const int recovery = static_cast<int>(std::lround(settings_.limit_recovery_s / prior_.sample_time_s));
  for (int j = 0; j < joints(); ++j) {
    for (int i = 0; i < samples_; ++i) {
      // Input i's set point reached the limit: entry k of the error is the output at sample k+1, the
      // first that input i moves; the valves' flow limit and the bounce-back shape them.
      if (std::abs(feedback_(i, j) + u_j(i, j)) < reach_bar_) continue;
      const int end = std::min(samples_, i + std::max(recovery, 1));
      learnable_.col(j).segment(i, end - i).setZero();
    }
  }
}

void LearnedModelNoilc::update(const Eigen::Ref<const Eigen::MatrixXd>& u_j,
                               const Eigen::Ref<const Eigen::MatrixXd>& e_j, Eigen::Ref<Eigen::MatrixXd> u_next) {
  if (u_j.rows() != samples_ || e_j.rows() != samples_ || u_j.cols() != joints() || e_j.cols() != joints()) {
    throw InputError("noilc-learned: the data are not " + std::to_string(samples_) + " x " + std::to_string(joints()));
  }
  if (!u_j.allFinite() || !e_j.allFinite())
    throw FaultError("learning law noilc-learned: the trial's data hold a NaN or an infinity");
  const int trial = report_.trial + 1;
  report_ = {};
  report_.trial = trial;
  if (has_context_) leave_out_limited_outputs(u_j);
  const double cost = e_j.squaredNorm();
  bool from_best = false;
  char text[400];
  if (has_previous_) {
    const Eigen::MatrixXd du = u_j - u_previous_;
    const Eigen::MatrixXd dy = e_previous_ - e_j;  // e = yD - y: the change of output
    const double measured = dy.norm();
    const auto miss = [&](const Eigen::MatrixXd& predicted) {
      return measured > 0.0 ? (dy - predicted).norm() / measured : 0.0;
    };
    const Eigen::MatrixXd predicted = model_.simulate(du), prior_predicted = prior_model_.simulate(du);
    report_.measured_change = measured;
    report_.prior_miss = miss(prior_predicted);
    // The model that planned u_j is judged on it; the refit model is judged on it too (out of sample:
    // fitted on the trials before), and the next update is planned by whichever of the refit model and
    // the prior predicted this trial better. A refit that has learned what the trials' large changes
    // showed but mispredicts the fine ones near convergence (a coupled arm's pose-dependent terms no
    // linear correction holds) then leaves the planning to the prior instead of steering it wrong.
    const double refit_model_miss = miss(predicted);
    report_.predicted_change = planned_with_prior_ ? prior_predicted.norm() : predicted.norm();
    report_.prediction_miss = planned_with_prior_ ? report_.prior_miss : refit_model_miss;
    plan_with_prior_ = prior_plans_always() || refit_model_miss > report_.prior_miss;
    if (cost > (1.0 + settings_.guard) * best_cost_) {
      report_.fell_back = true;
      from_best = true;
      step_ = std::max(kSmallestStep, 0.5 * step_);
      // Not learned from (what made it worse may be what the linear model cannot hold: a limit, a
      // disturbance); the data that taught the model count half, which is the ridge towards the prior
      // doubled: the model falls half way back to the prior.
      for (Eigen::MatrixXd& g : gram_) g *= 0.5;
      for (Eigen::VectorXd& b : moment_) b *= 0.5;
      data_scale_ *= 0.5;
      correction_ *= 0.5;
      rebuild();
      std::snprintf(
          text, sizeof text,
          "noilc-learned: trial %d raised ||e||^2 by %.0f %% over the best trial: the model falls half way back "
          "to the prior, the next update starts from the best trial with step %.3g",
          trial, 100.0 * (cost / best_cost_ - 1.0), step_);
      note_ = text;
    } else {
      // Within the guard but no descent (the cost is above the best trial's: at the noise floor, or
      // a model that mispredicts the last stretch): the trial's data are learned from (it is a fair
      // measurement), but the next update starts from the best trial with half the step, so the
      // learning stays a descent on the measured cost without forgetting what the model learned.
      // Several joints: within the slack of the best trial's cost is a descent too (the difference is noise).
      const bool descended = cost <= (1.0 + descent_slack()) * best_cost_;
      report_.within_slack = descended && cost > best_cost_;
      if (!descended) {
        from_best = true;
        report_.no_descent = true;
        step_ = std::max(kSmallestStep, 0.5 * step_);
      }
      if (settings_.refit && du.squaredNorm() > 0.0) {
        const Eigen::MatrixXd learnable = learnable_.cwiseProduct(learnable_previous_);
        report_.left_out = static_cast<int>(learnable.size() - static_cast<Eigen::Index>(learnable.sum()));
        refit(du, dy - prior_predicted, learnable);
        rebuild();
        report_.refitted = true;
        report_.refit_miss = miss(model_.simulate(du));
      }
      if (descended) step_ = std::min(1.0, 2.0 * step_);  // a trial that descended earns the step back
      std::snprintf(
          text, sizeof text,
          "noilc-learned: model %s from trial %d: predicted change of error %.4g, measured %.4g (miss %.0f %%; "
          "the prior alone %.0f %%, the refit %.0f %%)%s%s",
          report_.refitted ? "refit" : "kept", trial, report_.predicted_change, measured,
          100.0 * report_.prediction_miss, 100.0 * report_.prior_miss, 100.0 * report_.refit_miss,
          !descended             ? "; no descent: the next update starts from the best trial with a smaller step"
          : report_.within_slack ? "; within learned_joints_descent_slack of the best trial: planned from it"
                                 : "",
          prior_plans_always() ? "; the prior plans the next update (several joints)"
          : plan_with_prior_   ? "; the prior plans the next update (it predicted this trial better)"
                               : "");
      note_ = text;
    }
  }
  if (!has_previous_ || cost <= best_cost_) {
    u_best_ = u_j;
    e_best_ = e_j;
    learnable_best_ = learnable_;
    best_cost_ = cost;
  }
  report_.step = step_;
  report_.prior_plans = plan_with_prior_;
  // One joint: the update, like the refit, does not act on the outputs the pressure limit shaped: their
  // errors are zeroed (as noilc-constrained does; docs/learning-laws.md), so the correction does not
  // wind up against a limit the linear model cannot see.
  StateSpaceNoilc& planner = plan_with_prior_ ? prior_solver_ : solver_;
  planned_with_prior_ = plan_with_prior_;
  // Several joints (unless joints_zero_limited_errors): the refit leaves them out, the update does not:
  // arm3's wrist touches its limit every trial, and zeroed there its error was never corrected (1.29 deg
  // at iteration 10 against 0.975).
  const auto plan_from = [&](const Eigen::Ref<const Eigen::MatrixXd>& u, const Eigen::Ref<const Eigen::MatrixXd>& e,
                             const Eigen::MatrixXd& learnable) {
    if (zeroes_limited_errors()) planner.solve(u, e.cwiseProduct(learnable), u_next);
    else planner.solve(u, e, u_next);
    if (step_ < 1.0) u_next = u + step_ * (u_next - u);
  };
  if (from_best) plan_from(u_best_, e_best_, learnable_best_);
  else plan_from(u_j, e_j, learnable_);
  // The next trial's change is measured against the trial its correction was planned from.
  if (from_best) {
    u_previous_ = u_best_;
    e_previous_ = e_best_;
    learnable_previous_ = learnable_best_;
  } else {
    u_previous_ = u_j;
    e_previous_ = e_j;
    learnable_previous_ = learnable_;
  }
  has_previous_ = true;
  learnable_.setOnes();
  has_context_ = false;
}

std::optional<ModelCheck> LearnedModelNoilc::model_check() const {
  if (report_.trial < 2) return std::nullopt;  // the first update has no earlier trial to compare with
  return ModelCheck{report_.trial,           report_.predicted_change, report_.measured_change,
                    report_.prediction_miss, report_.refitted,         report_.fell_back};
}

std::string LearnedModelNoilc::take_note() {
  std::string note;
  note.swap(note_);
  return note;
}

}  // namespace bellows

namespace bellows {

LearnedNoilcSettings learned_noilc_settings(const IlcParameters& ilc) {
  LearnedNoilcSettings settings;
  settings.weights = {ilc.m, ilc.learned_s, ilc.w};
  settings.forgetting = ilc.learned_forgetting;
  settings.relative_ridge = ilc.learned_ridge;
  settings.guard = ilc.learned_guard;
  settings.shape.taps = ilc.learned_taps;
  settings.joints_refit_plans = ilc.learned_joints_refit_plans != 0;
  settings.joints_zero_limited_errors = ilc.learned_joints_zero_limited != 0;
  settings.joints_descent_slack = ilc.learned_joints_descent_slack;
  settings.limit_margin_bar = ilc.limit_margin_bar;
  settings.limit_recovery_s = ilc.limit_recovery_s;
  return settings;
}

}  // namespace bellows
