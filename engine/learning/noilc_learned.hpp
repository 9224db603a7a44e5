// Norm-optimal ILC on a model that learns from the trials it guides (`noilc-learned`).
//
// The paper's update predicts the next error with the arm's open-loop model, but the correction acts
// through the closed loop (PID with feed-forward, the pressure controllers' lag, the valves' flow
// limits, the bellows' bounce-back and creep). This law takes the closed loop computed from the known
// controller and the configured arm model as its prior (engine/learning/closed_loop_model) and, after
// every trial, refits a correction to it from what the trial showed: the change of output each change
// of correction produced, dy = -(e_j - e_ref) against du = u_j - u_ref (ref: the trial u_j was planned
// from). The correction (an FIR and low-passes per joint, in parallel with the prior) is a ridge fit of
// the prior's residual over the session's trials (estimation-based ILC; Weigand et al. 2021 identify
// the model from convergence data the same way, black-box). The ridge pulls towards the prior (a zero
// correction), weighted relative to the largest change of correction seen, and every trial's data
// stay in the fit (older ones discounted by `learned_forgetting`, 1 by default): trials near the noise
// floor, whose correction barely changed, add almost nothing, so the model cannot walk away from
// what the informative trials showed.
//
// What the refit does not learn from: outputs the pressure limit shaped (within `limit_recovery_s`
// after an input whose set point reached the limit in either trial of the pair, as noilc-constrained
// leaves them out) and held samples (no fresh reading: their error is a recorded 0, not a measurement;
// set_held_outputs); and trials that got worse.
//
// The guard keeps learning a descent on the measured cost ||e||^2: a trial whose cost rose above
// (1 + learned_guard) times the best trial's is not learned from; the model falls half way back to
// the prior (the ridge doubled relative to the data), and the next update starts again from the best
// trial with half the step (halved again for every further failure, down to 1/8; doubled back
// towards 1 by every trial that did not get worse).
//
// Several joints: each output's correction reads every joint's input (cross-joint, the coupling the
// prior has wrong), unless `cross_joint` is false (diagonal).
//
// The planner: each trial judges the refit model (fitted on the trials before) and the prior on how
// well they predicted its change of error; the better one plans the next update (the refit on a tie).
// Several joints: the prior plans every update unless `joints_refit_plans` (the refit still learns and
// is judged); the update zeroes the limit-shaped errors only with `joints_zero_limited_errors`; a trial
// within `joints_descent_slack` of the best trial's cost counts as a descent.
//
// Every refit and fall-back is reported as a note (take_note), which the session records as an event.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "engine/base/parameters.hpp"
#include "engine/learning/closed_loop_model.hpp"
#include "engine/learning/learning_law.hpp"
#include "engine/learning/noilc_state_space.hpp"

namespace bellows {

struct LearnedNoilcSettings {
  StateSpaceNoilcWeights weights;
  CorrectionShape shape;
  double forgetting = 1.0;         // weight of the older trials' data per trial, in (0, 1]
  double relative_ridge = 1e-3;    // ridge of the correction's fit, relative to the data's scale
  double guard = 0.25;             // relative rise of ||e||^2 over the best trial that counts as worse
  bool refit = true;               // false: the prior only (what the closed loop alone does)
  double limit_margin_bar = 0.0;   // a set point within this of the pressure limit is on the limit
  double limit_recovery_s = 0.08;  // outputs this long after an input on the limit are not learned from
  bool cross_joint = true;         // several joints: each output's correction from every joint's input
  // Several joints only: the refit model may plan (when it predicted the last trial better than the prior); false:
  // the prior plans every update. On arm2/arm3 the refit's early steps were the wrong ones (docs/learning-laws.md).
  bool joints_refit_plans = false;
  // Several joints only: the update zeroes the errors the pressure limit shaped (false: only the refit leaves them
  // out). Zeroed, a wrist that touches its limit every trial never has those errors corrected.
  bool joints_zero_limited_errors = false;
  // Several joints only: a trial whose ||e||^2 is above the best trial's by no more than this fraction counts as a
  // descent (planned from, the step not halved) instead of a no-descent. Near the floor a trial-to-trial difference
  // of a few percent is noise, and replaying the same step from the best trial stalls the law there (arm2/arm3).
  double joints_descent_slack = 0.05;
};

/// What the last update did, for the session and the console.
struct LearnedNoilcReport {
  int trial = 0;                  // updates made so far
  bool refitted = false;          // the model was refit from the last trial
  bool fell_back = false;         // the last trial got worse: back to the prior and the best trial
  bool no_descent = false;        // the last trial's cost was above the best's (beyond the slack, within the guard)
  bool within_slack = false;      // ... but within joints_descent_slack of it: planned from all the same
  double step = 1.0;              // the fraction of the norm-optimal step taken
  double measured_change = 0.0;   // ||e_j - e_{j-1}|| (normalized units)
  double predicted_change = 0.0;  // ||P_model (u_j - u_{j-1})|| with the model that planned u_j
  double prediction_miss = 0.0;   // ||-(e_j - e_{j-1}) - P_model du|| / ||e_j - e_{j-1}||, same model
  bool prior_plans = false;       // the next update is planned by the prior (it predicted this trial better)
  double prior_miss = 0.0;        // the same with the prior alone
  double refit_miss = 0.0;        // the same with the model refit from this trial
  int left_out = 0;               // output entries the refit did not learn from (limit-shaped, held)
};

class LearnedModelNoilc {
 public:
  /// Throws InputError for bad settings or weights.
  LearnedModelNoilc(const ClosedLoopPrior& prior, const LearnedNoilcSettings& settings, int samples);

  /// u_next from (u_j, e_j), each N x J; refits the model first when there is a previous trial.
  void update(const Eigen::Ref<const Eigen::MatrixXd>& u_j, const Eigen::Ref<const Eigen::MatrixXd>& e_j,
              Eigen::Ref<Eigen::MatrixXd> u_next);

  int samples() const { return samples_; }
  int joints() const { return prior_.joints(); }
  const LearnedNoilcReport& last_report() const { return report_; }
  /// The learned coefficients as closed_loop_model takes them: per_joint() x J, or per_joint() J x J
  /// with cross_joint (several joints).
  const Eigen::MatrixXd& correction() const { return correction_; }
  /// The coefficients of one output's correction: per_joint(), times J with cross_joint.
  int coefficients_per_output() const {
    return settings_.shape.per_joint() * (settings_.cross_joint ? prior_.joints() : 1);
  }
  /// The note for the session's events since the last call (empty if none), then cleared.
  std::string take_note();
  /// As LearningLaw::model_check: from the last report, from the second update on.
  std::optional<ModelCheck> model_check() const;
  /// As LearningLaw::set_input_context, N x J: before update(); marks the outputs the pressure limit
  /// shaped in this trial as not learnable.
  void set_input_context(const Eigen::Ref<const Eigen::MatrixXd>& feedback_bar, double input_limit_bar);
  /// Before update(): held(k) != 0 for the samples k = 0..N of this trial taken without a fresh reading;
  /// their outputs (error entries k - 1) are not learned from. Cleared by update().
  void set_held_outputs(const std::vector<unsigned char>& held);

 private:
  /// residual: the change of output the prior leaves unexplained, dy - P_prior du.
  void refit(const Eigen::MatrixXd& du, const Eigen::MatrixXd& residual, const Eigen::MatrixXd& learnable);
  void rebuild();
  void leave_out_limited_outputs(const Eigen::Ref<const Eigen::MatrixXd>& u_j);
  bool prior_plans_always() const { return joints() > 1 && !settings_.joints_refit_plans; }
  bool zeroes_limited_errors() const { return joints() == 1 || settings_.joints_zero_limited_errors; }
  double descent_slack() const { return joints() > 1 ? settings_.joints_descent_slack : 0.0; }

  ClosedLoopPrior prior_;
  LearnedNoilcSettings settings_;
  int samples_;
  StateSpaceModel prior_model_, model_;
  StateSpaceNoilc solver_, prior_solver_;            // on the refit model, on the prior
  bool plan_with_prior_ = false;                     // the prior predicted the last trial better than the refit model
  bool planned_with_prior_ = false;                  // ... and planned the trial being measured
  Eigen::MatrixXd correction_;                       // coefficients_per_output() x J
  std::vector<Eigen::MatrixXd> gram_;                // per output joint
  std::vector<Eigen::VectorXd> moment_;              // per output joint
  Eigen::VectorXd data_scale_;                       // per output joint: the largest mean square regressor of one trial
  Eigen::MatrixXd regressors_, masked_, increment_;  // the refit's workspace: N x q, N x q, q x q
  double increment_scale_ = 0.0;
  Eigen::MatrixXd u_previous_, e_previous_, u_best_, e_best_, planned_;
  Eigen::MatrixXd feedback_;  // N x J: this trial's feedback (bar), with has_context_
  double reach_bar_ = 0.0;
  bool has_context_ = false;
  Eigen::MatrixXd learnable_, learnable_previous_, learnable_best_;  // N x J: 1 where the output may be learned from
  bool has_previous_ = false;
  double best_cost_ = 0.0;
  double step_ = 1.0;
  LearnedNoilcReport report_;
  std::string note_;
};

}  // namespace bellows

namespace bellows {

/// `noilc-learned` for one joint, as a LearningLaw.
class NoilcLearnedLaw final : public LearningLaw {
 public:
  NoilcLearnedLaw(const ClosedLoopPrior& prior, const LearnedNoilcSettings& settings, int samples)
      : core_(prior, settings, samples) {}
  void update(const Eigen::Ref<const Eigen::VectorXd>& u_j, const Eigen::Ref<const Eigen::VectorXd>& e_j,
              Eigen::Ref<Eigen::VectorXd> u_next) override {
    core_.update(u_j, e_j, u_next);
  }
  void set_input_context(const Eigen::Ref<const Eigen::VectorXd>& feedback_bar, double input_limit_bar) override {
    core_.set_input_context(feedback_bar, input_limit_bar);
  }
  void set_held_outputs(const std::vector<unsigned char>& held) override { core_.set_held_outputs(held); }
  std::string name() const override { return "noilc-learned"; }
  int samples() const override { return core_.samples(); }
  std::string take_note() override { return core_.take_note(); }
  std::optional<ModelCheck> model_check() const override { return core_.model_check(); }
  const LearnedModelNoilc& core() const { return core_; }

 private:
  LearnedModelNoilc core_;
};

/// The settings of `[ilc]`'s noilc-learned keys.
LearnedNoilcSettings learned_noilc_settings(const IlcParameters& ilc);

}  // namespace bellows
