// The input buffer (input_buffer.hpp): linear resampling of known samples, the newest
// held, staleness against the timeout and the stale policies, the ring's wrap, and the
// filtered wrench read out of a bank, against numbers worked by hand.
#include <joint_load_estimator/estimation/estimator.hpp>  // StalePolicy
#include <joint_load_estimator/estimation/input_buffer.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace {

using Vector6 = jle::InputBuffer::Vector6;

Vector6 v6(double a, double b, double c, double d, double e, double f) {
  Vector6 v;
  v << a, b, c, d, e, f;
  return v;
}

// Samples at t = 1, 2, 4 s; the values are small integers and the interpolation
// weights below are sums of powers of two, so every expected value is exact.
jle::InputBuffer threeSamples(jle::StalePolicy policy = jle::StalePolicy::kHold) {
  jle::InputBuffer b(0.5, policy);
  EXPECT_TRUE(b.add(1.0, v6(0, 4, -8, 1, 2, 3)));
  EXPECT_TRUE(b.add(2.0, v6(4, 0, 8, 1, 6, -1)));
  EXPECT_TRUE(b.add(4.0, v6(8, 8, 0, 5, 6, 7)));
  return b;
}

TEST(InputBuffer, LinearBetweenTheSamplesAroundT) {
  const jle::InputBuffer b = threeSamples();
  EXPECT_EQ(b.count(), 3);
  // t = 1.25: 3/4 of the first, 1/4 of the second.
  EXPECT_EQ(b.interpolate(1.25), v6(1, 3, -4, 1, 3, 2));
  // t = 3: halfway between the second and the third.
  EXPECT_EQ(b.interpolate(3.0), v6(6, 4, 4, 3, 6, 3));
  // On a sample: that sample.
  EXPECT_EQ(b.interpolate(2.0), v6(4, 0, 8, 1, 6, -1));
}

TEST(InputBuffer, NewestHeldPastItOldestBeforeItZeroWithoutSamples) {
  const jle::InputBuffer b = threeSamples();
  EXPECT_EQ(b.interpolate(4.0), v6(8, 8, 0, 5, 6, 7));
  EXPECT_EQ(b.interpolate(100.0), v6(8, 8, 0, 5, 6, 7));
  EXPECT_EQ(b.interpolate(0.0), v6(0, 4, -8, 1, 2, 3));
  const jle::InputBuffer empty(0.5, jle::StalePolicy::kHold);
  EXPECT_EQ(empty.interpolate(1.0), Vector6::Zero());
  EXPECT_TRUE(empty.staleAt(1.0));
}

TEST(InputBuffer, DropsSamplesNotNewerOrNotFinite) {
  jle::InputBuffer b = threeSamples();
  EXPECT_FALSE(b.add(4.0, Vector6::Ones()));  // same stamp
  EXPECT_FALSE(b.add(3.0, Vector6::Ones()));  // older
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(b.add(5.0, v6(0, 0, nan, 0, 0, 0)));
  EXPECT_FALSE(b.add(nan, Vector6::Ones()));
  EXPECT_EQ(b.count(), 3);
  EXPECT_EQ(b.interpolate(10.0), v6(8, 8, 0, 5, 6, 7));
}

// Timeout 0.5 s after the newest sample at 4 s: 4.5 is still fresh (equal is not
// older), 4.5 + 2^-20 is stale; a time before the newest is never stale.
TEST(InputBuffer, StaleOnlyOlderThanTheTimeout) {
  const jle::InputBuffer b = threeSamples();
  EXPECT_FALSE(b.staleAt(3.0));
  EXPECT_FALSE(b.staleAt(4.5));
  EXPECT_TRUE(b.staleAt(4.5 + std::ldexp(1.0, -20)));
}

TEST(InputBuffer, PoliciesOfAStaleInput) {
  const double late = 5.0;
  const jle::InputBuffer hold = threeSamples(jle::StalePolicy::kHold);
  const jle::InputBuffer zero = threeSamples(jle::StalePolicy::kZero);
  EXPECT_EQ(hold.valueAt(late), v6(8, 8, 0, 5, 6, 7));
  EXPECT_EQ(zero.valueAt(late), Vector6::Zero());
  // Fresh, the policy does not matter.
  EXPECT_EQ(zero.valueAt(3.0), v6(6, 4, 4, 3, 6, 3));

  double out[6] = {0, 0, 0, 0, 0, 0};
  for (jle::StalePolicy p :
       {jle::StalePolicy::kHold, jle::StalePolicy::kZero, jle::StalePolicy::kStop}) {
    jle::InputBuffer b = threeSamples(p);
    EXPECT_TRUE(b.stale());  // before the first joint sample
    b.resample(3.0, true, out);
    EXPECT_FALSE(b.stale());
    EXPECT_FALSE(b.zeroed());
    EXPECT_FALSE(b.stopped());
    b.resample(late, true, out);
    EXPECT_TRUE(b.stale());
    EXPECT_EQ(b.zeroed(), p == jle::StalePolicy::kZero);
    EXPECT_EQ(b.stopped(), p == jle::StalePolicy::kStop);
  }
}

TEST(InputBuffer, ResampleWritesSixChannelsOrSkipsAnUnneededInput) {
  jle::InputBuffer b = threeSamples(jle::StalePolicy::kStop);
  double out[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
  b.resample(1.25, true, out + 1);
  EXPECT_EQ(out[0], -1.0);
  EXPECT_EQ(out[7], -1.0);
  for (int j = 0; j < 6; ++j) EXPECT_EQ(out[1 + j], v6(1, 3, -4, 1, 3, 2)[j]);
  // Not needed: nothing read, never stale (even long after the newest sample).
  double untouched[6] = {7, 7, 7, 7, 7, 7};
  b.resample(100.0, false, untouched);
  EXPECT_FALSE(b.stale());
  EXPECT_FALSE(b.stopped());
  for (double u : untouched) EXPECT_EQ(u, 7.0);
}

// 600 samples, value k at t = k: the ring keeps the last 512 (k = 88..599).
TEST(InputBuffer, RingKeepsTheLatestSamples) {
  jle::InputBuffer b(1.0, jle::StalePolicy::kHold);
  for (int k = 0; k < 600; ++k) ASSERT_TRUE(b.add(k, Vector6::Constant(k)));
  EXPECT_EQ(b.count(), jle::InputBuffer::kHistory);
  EXPECT_EQ(b.interpolate(598.5), Vector6::Constant(598.5));
  EXPECT_EQ(b.interpolate(100.25), Vector6::Constant(100.25));
  EXPECT_EQ(b.interpolate(88.0), Vector6::Constant(88.0));
  EXPECT_EQ(b.interpolate(10.0), Vector6::Constant(88.0));  // older than all held
}

TEST(InputBuffer, ResetForgetsEverything) {
  jle::InputBuffer b = threeSamples();
  double out[6];
  b.resample(3.0, true, out);
  b.reset();
  EXPECT_EQ(b.count(), 0);
  EXPECT_TRUE(b.stale());
  EXPECT_EQ(b.interpolate(3.0), Vector6::Zero());
  EXPECT_TRUE(b.add(0.5, Vector6::Ones()));  // older than before the reset: accepted
}

// A bank of 15 channels holding a wrench at channels 4..9: the 3-point difference of a
// straight line returns its value at the newest sample, force then moment. Tolerance:
// the weights for samples 1 ms apart sum to 1 within ~1e-12 relative (the QR's
// rounding, conditioned by the scaling of time); the values are at most 60.
TEST(InputBuffer, FilteredWrenchReadsItsSixChannels) {
  jle::DifferentiatorConfig c;
  c.type = jle::DifferentiatorType::kFiniteDifference;
  jle::DifferentiatorBank bank(c, 15);
  double x[15];
  for (int k = 0; k < 3; ++k) {
    const double t = 1.0 + 1e-3 * k;
    for (int i = 0; i < 15; ++i) x[i] = (i + 1) * (1.0 + 2.0 * (t - 1.0));
    bank.update(t, x);
  }
  const jle::Wrench<double> w = jle::filteredWrench(bank, 4);
  const double scale = 1.0 + 2.0 * 2e-3;  // the line at the newest sample
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(w.force[j], (5 + j) * scale, 1e-10);
    EXPECT_NEAR(w.moment[j], (8 + j) * scale, 1e-10);
  }
}

}  // namespace

// centredAt (a delayed estimate's read: the smoothed stream's): the least-squares line
// through the samples within half of t, at t. A line passes exactly wherever the samples
// lie; noise symmetric about it cancels; with samples on one side only, interpolate().
TEST(InputBuffer, CentredAtFitsTheLineThroughTheSamplesAroundT) {
  jle::InputBuffer b(0.5, jle::StalePolicy::kHold);
  // A line 3 + 2 t in every component, at irregular stamps, with +-0.5 added to the
  // samples at 1.00 and 1.04 s and -0.5 to those at 0.98 and 1.02 s (pairs symmetric
  // about t = 1.01: the noise's fit is zero there).
  const double stamps[] = {0.90, 0.98, 1.00, 1.02, 1.04, 1.20};
  const double noise[] = {0.0, -0.5, 0.5, -0.5, 0.5, 0.0};
  for (int k = 0; k < 6; ++k)
    ASSERT_TRUE(b.add(stamps[k], Vector6::Constant(3.0 + 2.0 * stamps[k] + noise[k])));
  // Within 0.035 of 1.01: the four noisy samples, at u = -0.03, -0.01, 0.01, 0.03 from t
  // (sum 0): the fit's value at u = 0 is the line's, 5.02, plus the noise's mean, 0.
  EXPECT_NEAR(b.centredAt(1.01, 0.035)[0], 5.02, 1e-12);
  // A window holding two clean samples only (0.90 and 1.20 about 1.05): the line itself.
  jle::InputBuffer clean(0.5, jle::StalePolicy::kHold);
  for (double t : {0.90, 1.20, 1.50}) ASSERT_TRUE(clean.add(t, Vector6::Constant(3.0 + 2.0 * t)));
  EXPECT_NEAR(clean.centredAt(1.05, 0.2)[3], 5.1, 1e-12);
  // Samples on one side only (none after 1.5 s): interpolate(), the newest held.
  EXPECT_EQ(clean.centredAt(1.6, 0.2), clean.interpolate(1.6));
  // None within half: interpolate().
  EXPECT_EQ(clean.centredAt(1.0, 0.01), clean.interpolate(1.0));
}
