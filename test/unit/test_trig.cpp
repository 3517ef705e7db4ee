// sinCos (trig.hpp) against long double sinl/cosl (x87, 64-bit mantissa: an independent
// reference 2000 times finer than double's ulp), and its fallback.
#include <joint_load_estimator/portable_random.hpp>
#include <joint_load_estimator/trig.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace {

// Largest |error| of sinCos<double> over n uniform angles in [-range, range].
double worstError(double range, int n) {
  jle::PortableRandom random(7);
  double worst = 0.0;
  for (int k = 0; k < n; ++k) {
    const double q = random.uniform(-range, range);
    double s, c;
    jle::sinCos(q, s, c);
    const long double q_l = q;
    worst = std::max(worst, static_cast<double>(std::fabs(s - std::sin(q_l))));
    worst = std::max(worst, static_cast<double>(std::fabs(c - std::cos(q_l))));
  }
  return worst;
}

TEST(SinCos, WithinAnUlpOfTheExactValue) {
  // ulp(1) = 2.2e-16: fdlibm's kernels are within 1 ulp; measured 8.7e-17 at every range.
  for (double range : {0.5, 1.0, 3.2, 7.0, 100.0, 1e4, jle::kFastTrigLimit})
    EXPECT_LT(worstError(range, 200000), 1.2e-16) << "range " << range;
}

TEST(SinCos, ExactWhereTheValuesAre) {
  double s, c;
  jle::sinCos(0.0, s, c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  // Quadrant boundaries: the sign and the swap of the kernels (pi/2 is not a double:
  // sin is 1 to the last bit, cos the tiny remainder).
  const double half_pi = M_PI / 2;
  for (int n = -8; n <= 8; ++n) {
    jle::sinCos(n * half_pi, s, c);
    EXPECT_NEAR(s, std::sin(static_cast<long double>(n * half_pi)), 1e-16) << n;
    EXPECT_NEAR(c, std::cos(static_cast<long double>(n * half_pi)), 1e-16) << n;
  }
  jle::sinCos(half_pi, s, c);
  EXPECT_EQ(s, 1.0);
  jle::sinCos(-half_pi, s, c);
  EXPECT_EQ(s, -1.0);
}

TEST(SinCos, BeyondTheLimitAndOtherTypesAreTheCLibrarys) {
  for (double q : {1.5 * jle::kFastTrigLimit, -3e9, 1e300}) {
    double s, c;
    jle::sinCos(q, s, c);
    EXPECT_EQ(s, std::sin(q)) << q;
    EXPECT_EQ(c, std::cos(q)) << q;
  }
  double s, c;
  jle::sinCos(std::numeric_limits<double>::quiet_NaN(), s, c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
  jle::sinCos(std::numeric_limits<double>::infinity(), s, c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
  float sf, cf;
  jle::sinCos(0.7f, sf, cf);
  EXPECT_EQ(sf, std::sin(0.7f));
  EXPECT_EQ(cf, std::cos(0.7f));
}

}  // namespace
