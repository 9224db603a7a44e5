// What "iteration" means, in one place (docs/iterations.md): iterations are numbered from 0, the
// paper's way. Iteration 0 is the first trial (feedback only, or a transferred correction); iteration
// k >= 1 applies the correction learned from iteration k - 1. "Run K iterations" (`run --iterations
// K`, the console's `N` with K) runs K learning iterations after the newest one, and iteration 0
// first when there is none: from scratch it ends at iteration K.
#pragma once

#include <string>

namespace bellows {

/// Trials that "run K iterations" takes: K + 1 from scratch (iteration 0, then 1..K), K after
/// completed iterations.
inline int trials_for_iterations(int iterations, bool has_iterations) {
  return has_iterations ? iterations : iterations + 1;
}

/// The iterations a session of `count` iterations holds, as people read them: "0..5", "0", "none".
inline std::string iteration_range(long long count) {
  if (count <= 0) return "none";
  if (count == 1) return "0";
  return "0.." + std::to_string(count - 1);
}

}  // namespace bellows
