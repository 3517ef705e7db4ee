// The package's random numbers (the tools' generators, the accuracy study's ground
// truth, the tests' random models): the same from every standard library. They come
// from std::mt19937, whose output the standard fixes ([rand.predef]), through the
// mappings written out below, never through <random>'s distributions (whose algorithms
// each library chooses). What is derived from them then depends only on the libm's sin,
// cos, log and sqrt, which agree to the last bit or two across platforms.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

namespace jle {

/// Uniform and normal random numbers, deterministic from a seed and portable.
class PortableRandom {
 public:
  /// std::mt19937 seeded with the 32 bits seed XOR (seed >> 32): a seed below 2^32 as
  /// it is.
  explicit PortableRandom(std::uint64_t seed)
      : engine_(static_cast<std::uint32_t>(seed ^ (seed >> 32))) {}

  /// Uniform in [0, 1) with 53 random bits: (a 2^26 + b) / 2^53 with a = (first draw)
  /// >> 5 and b = (second draw) >> 6 (MT19937's genrand_res53).
  double uniform() {
    const std::uint32_t a = static_cast<std::uint32_t>(engine_()) >> 5;  // 27 bits
    const std::uint32_t b = static_cast<std::uint32_t>(engine_()) >> 6;  // 26 bits
    return (a * 67108864.0 + b) * (1.0 / 9007199254740992.0);
  }
  /// Uniform in [lo, hi): lo + (hi - lo) * uniform().
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Integer in [0, n) for n > 0: floor(n * uniform()).
  int index(int n) { return std::min(static_cast<int>(uniform() * n), n - 1); }
  /// Standard normal by Box-Muller: u1 = 1 - uniform() (in (0, 1]), u2 = uniform(),
  /// r = sqrt(-2 ln u1); returns r cos(2 pi u2), and r sin(2 pi u2) at the next call.
  double gaussian() {
    constexpr double kTwoPi = 6.283185307179586;
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform();  // (0, 1]: the logarithm stays finite
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(kTwoPi * u2);
    has_spare_ = true;
    return r * std::cos(kTwoPi * u2);
  }

 private:
  std::mt19937 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace jle
