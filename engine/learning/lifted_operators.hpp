// The lifted trial map P of a discrete model (u(0..N-1) -> y(1..N), one step of delay) applied
// without ever forming the N x N matrix: a forward simulation for P v, a backward (adjoint)
// simulation for P' e, both O(N). Also P's symbol on the unit circle, for frequency analysis.
#pragma once

#include <complex>

#include <Eigen/Dense>

#include "engine/model/arm_model.hpp"

namespace bellows {

/// out = P v. `out` must not alias `v`.
void apply_lifted(const DiscreteArmModel& model, const Eigen::Ref<const Eigen::VectorXd>& v,
                  Eigen::Ref<Eigen::VectorXd> out);

/// out = P' e. `out` must not alias `e`.
void apply_lifted_transpose(const DiscreteArmModel& model, const Eigen::Ref<const Eigen::VectorXd>& e,
                            Eigen::Ref<Eigen::VectorXd> out);

/// sum_k C A^k B e^{-i k theta}: how P acts on an everlasting sinusoid of `theta` rad per sample.
std::complex<double> lifted_symbol(const DiscreteArmModel& model, double theta_rad_per_sample);

/// Largest singular value of P for N samples (power iteration on P'P, relative accuracy ~1e-6).
double lifted_norm(const DiscreteArmModel& model, int samples);

}  // namespace bellows
