// sinCos (trig.hpp) against long double sinl/cosl (x87, 64-bit mantissa: an independent
// reference 2000 times finer than double's ulp), and its fallback.
#include <joint_load_estimator/io/portable_random.hpp>
#include <joint_load_estimator/model/trig.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

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

// sinCosMany gathers the angles for sinCosArray, which takes them 8, 4 and 2 at a time
// in vector registers: each lane must give the bits of sinCos (the same operations), in
// every quadrant, over an odd count (the last angle alone), through an index map, with a
// group that has a large or non-finite angle falling back to sinCos for all of it.
TEST(SinCos, ManyAtOnceAreSinCosBitForBit) {
  jle::PortableRandom random(11);
  std::vector<double> q;
  for (int k = 0; k < 4000; ++k) q.push_back(random.uniform(-20.0, 20.0));
  for (int n = -8; n <= 8; ++n) q.push_back(n * M_PI / 2);
  q.insert(q.end(), {0.0, -0.0, 1e-300, jle::kFastTrigLimit, -jle::kFastTrigLimit, 3e9, 0.25,
                     std::numeric_limits<double>::quiet_NaN(), 0.5,
                     std::numeric_limits<double>::infinity(), -1.0});
  const int count = static_cast<int>(q.size());
  ASSERT_EQ(count % 2, 0);
  // All of them but the first (an odd count), in reverse through the index map.
  std::vector<double> s(q.size(), 7.0), c(q.size(), 7.0);
  jle::sinCosMany(
      count - 1, [count](int j) { return count - 1 - j; }, q.data(), s.data(), c.data());
  EXPECT_EQ(s[0], 7.0);  // not listed: untouched
  for (int k = 1; k < count; ++k) {
    double s1, c1;
    jle::sinCos(q[k], s1, c1);
    if (std::isnan(q[k]) || std::isinf(q[k])) {
      EXPECT_TRUE(std::isnan(s[k]) && std::isnan(c[k])) << q[k];
      continue;
    }
    EXPECT_EQ(s[k], s1) << "q = " << q[k];
    EXPECT_EQ(c[k], c1) << "q = " << q[k];
    EXPECT_EQ(std::signbit(s[k]), std::signbit(s1)) << "q = " << q[k];
  }
  // More than one gathered block of sinCosMany (64 angles each), in order.
  std::vector<double> s2(q.size()), c2(q.size());
  jle::sinCosMany(
      count, [](int j) { return j; }, q.data(), s2.data(), c2.data());
  for (int k = 1; k < count; ++k) {
    if (std::isnan(q[k]) || std::isinf(q[k])) continue;
    EXPECT_EQ(s2[k], s[k]) << "q = " << q[k];
    EXPECT_EQ(c2[k], c[k]) << "q = " << q[k];
  }
  // Other scalar types: sinCos one by one.
  std::vector<float> qf = {0.1f, -2.0f, 3.0f}, sf(3), cf(3);
  jle::sinCosMany(
      3, [](int j) { return j; }, qf.data(), sf.data(), cf.data());
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(sf[k], std::sin(qf[k]));
    EXPECT_EQ(cf[k], std::cos(qf[k]));
  }
}

// Every path this CPU can take (the generic vectors always; AVX2, AVX-512F where the CPU
// has them), over every count from 0 to 40 (groups of 8, 4, 2 and one alone), with a
// large, an infinite or a NaN angle at each position of a group: the bits of sinCos, and
// nothing written past count.
TEST(SinCos, EveryVectorPathGivesSinCosBitForBit) {
  const jle::TrigPath paths[] = {jle::TrigPath::kGeneric, jle::TrigPath::kAvx2,
                                 jle::TrigPath::kAvx512};
  const char* names[] = {"generic", "avx2", "avx512"};
  const double odd[] = {3e9, std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::quiet_NaN(), -jle::kFastTrigLimit};
  jle::PortableRandom random(5);
  int paths_run = 0;
  for (int p = 0; p < 3; ++p) {
    if (!jle::trigPathSupported(paths[p])) {
      std::printf("[ INFO     ] this CPU cannot take the %s path\n", names[p]);
      continue;
    }
    ++paths_run;
    for (int count = 0; count <= 40; ++count) {
      for (int bad = -1; bad < count; ++bad) {
        std::vector<double> q(count + 1, 0.0);
        for (int k = 0; k < count; ++k) q[k] = random.uniform(-40.0, 40.0);
        if (bad >= 0) q[bad] = odd[bad % 4];
        std::vector<double> s(count + 1, 7.0), c(count + 1, 7.0);
        jle::sinCosArray(paths[p], count, q.data(), s.data(), c.data());
        ASSERT_EQ(s[count], 7.0) << names[p] << ", count " << count;
        ASSERT_EQ(c[count], 7.0) << names[p] << ", count " << count;
        for (int k = 0; k < count; ++k) {
          double s1, c1;
          jle::sinCos(q[k], s1, c1);
          if (std::isnan(s1)) {
            ASSERT_TRUE(std::isnan(s[k]) && std::isnan(c[k])) << names[p] << ", q = " << q[k];
            continue;
          }
          ASSERT_EQ(s[k], s1) << names[p] << ", count " << count << ", q = " << q[k];
          ASSERT_EQ(c[k], c1) << names[p] << ", count " << count << ", q = " << q[k];
          ASSERT_EQ(std::signbit(s[k]), std::signbit(s1)) << names[p] << ", q = " << q[k];
        }
      }
    }
  }
  EXPECT_GE(paths_run, 1);
  EXPECT_TRUE(jle::trigPathSupported(jle::trigPath()));
  std::printf("[ INFO     ] sinCosArray takes the %s path here; %d path(s) checked\n",
              names[static_cast<int>(jle::trigPath())], paths_run);
}

}  // namespace
