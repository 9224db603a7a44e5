// A deterministic, serializable Gaussian noise source (xoshiro256** + Box-Muller without caching),
// so that a simulation's random state can be saved and resumed bit for bit.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace bellows {

class GaussianNoise {
 public:
  using State = std::array<std::uint64_t, 4>;

  explicit GaussianNoise(std::uint64_t seed = 1) { reseed(seed); }

  void reseed(std::uint64_t seed) {
    // splitmix64 expands the seed into a full, never-all-zero state.
    for (auto& word : state_) {
      seed += 0x9E3779B97F4A7C15ULL;
      std::uint64_t z = seed;
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
      word = z ^ (z >> 31);
    }
  }

  /// A standard normal sample.
  double standard_normal() {
    const double u1 = uniform_open();
    const double u2 = uniform_open();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }

  const State& state() const { return state_; }
  void set_state(const State& state) { state_ = state; }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

  std::uint64_t next() {
    const std::uint64_t result = rotl(state_[1] * 5, 7) * 9;
    const std::uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = rotl(state_[3], 45);
    return result;
  }

  /// Uniform in (0, 1): never 0, so log() is finite.
  double uniform_open() { return (static_cast<double>(next() >> 11) + 0.5) * 0x1.0p-53; }

  State state_{};
};

}  // namespace bellows
