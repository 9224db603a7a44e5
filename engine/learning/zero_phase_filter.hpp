// Zero-phase low-pass Q-filter for ILC: a second-order Butterworth section run forward, then
// backward over the whole trial (filtfilt), so it removes high frequencies without delaying the
// correction. Each pass starts in the steady state of its first input sample, which keeps a trial
// that starts and ends at rest free of edge transients.
#pragma once

#include <Eigen/Dense>

namespace bellows {

class ZeroPhaseLowPass {
 public:
  /// Throws InputError unless 0 < cutoff < Nyquist (1 / (2 T)).
  ZeroPhaseLowPass(double cutoff_hz, double sample_time_s);

  /// out = Q in. `out` may alias `in`.
  void apply(const Eigen::Ref<const Eigen::VectorXd>& in, Eigen::Ref<Eigen::VectorXd> out) const;
  /// |H(e^{i theta})|^2: the (real, non-negative) response of the forward-backward pair.
  double gain(double theta_rad_per_sample) const;

 private:
  double b0_, b1_, b2_, a1_, a2_;
};

}  // namespace bellows
