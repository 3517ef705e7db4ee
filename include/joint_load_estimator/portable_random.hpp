// Uniform random numbers that are the same from every standard library (the standard
// fixes std::mt19937's sequence but not its distributions), for the generators.
#pragma once

#include <cstdint>
#include <random>

namespace jle {

/// Uniform numbers in [0, 1) with 53 random bits.
class Uniform {
 public:
  explicit Uniform(std::uint32_t seed) : generator_(seed) {}
  double operator()() {
    const std::uint32_t a = static_cast<std::uint32_t>(generator_()) >> 5;  // 27 bits
    const std::uint32_t b = static_cast<std::uint32_t>(generator_()) >> 6;  // 26 bits
    return (a * 67108864.0 + b) * (1.0 / 9007199254740992.0);
  }
  double operator()(double lo, double hi) { return lo + (hi - lo) * (*this)(); }

 private:
  std::mt19937 generator_;
};

}  // namespace jle
