// The error bounds the core and the filters guarantee, derived from the sweeps of
// bench/stability.cpp (docs/studies/stability.md) with the margin stated. test_stability.cpp
// asserts them on representative points; the bench checks every measured point and
// fails if one exceeds its bound. Change a bound only with new measurements.
#pragma once

#include <limits>

namespace jle_test {
namespace bounds {

/// Relative error of the joint wrenches (|(dF, dM)| / |(F, M)|, worst joint) of a
/// random serial chain or tree of n joints, in units of the scalar's epsilon
/// (2.2e-16 in double, 1.2e-7 in float). Measured worst over 400 samples (n <= 100) or
/// 50 (n >= 200): 1.5 eps at n = 1, 68 eps at n = 20 (one chain whose wrench at a joint
/// nearly cancels), 240 eps at n = 1000 in double; 1.8, 44 and 370 eps in float. The
/// growth is sub-linear (about n^0.6 from 100 to 1000: the roundings add like a random
/// walk); the bound grows linearly, with a floor for the conditioning of a single
/// joint's sum: margin 5.3 at the n = 20 outlier in double, at least 8 elsewhere. The
/// moment alone, where it nearly cancels at some joint of a long chain, reaches 860 eps
/// (double) and 2900 eps (float) at n = 1000 and is not bounded here.
inline double chainEps(int n) { return 300.0 + 3.0 * n; }

/// Relative error of the joint wrenches and, separately, of the joint moments
/// (|dM| / |M|), in units of epsilon, for the sweeps on models of up to 20 joints: mass
/// and inertia ratios to 1e9, link lengths 1e-4 to 1e2 m, angular velocities to 1e3
/// rad/s, rods (a principal moment 0), the base 1e6 m from the world origin, and the
/// singular configurations (wrench only there: a moment that vanishes by symmetry,
/// e.g. the UR5 stretched upwards at rest, has no relative error to speak of). Worst
/// measured: wrench 63 eps (double, 100 m links) and 42 eps (float, the same); moment
/// 117 eps (double, 1e3 rad/s) and 160 eps (float, world offset). Bound 1000 eps:
/// margin >= 6.
constexpr double kGenericEps = 1000.0;

template <typename Scalar>
double chain(int n) {
  return chainEps(n) * static_cast<double>(std::numeric_limits<Scalar>::epsilon());
}
template <typename Scalar>
double generic() {
  return kGenericEps * static_cast<double>(std::numeric_limits<Scalar>::epsilon());
}

/// Savitzky-Golay and finite-difference second derivatives: error of the bank's
/// weights applied to the window, over the error that rounding the samples alone causes
/// (eps sum |c_k x_k| with the exact weights c). Measured with one interval of 1e-4 to
/// 1e-10 s among 1 ms ones, 3- and 4-point differences, SG 9/2 and 7/5: at most 1.1
/// since the weights come from a QR factorisation (the normal equations reached 4.4e6).
/// Bound 5: margin 4.5.
constexpr double kWeightsRatio = 5.0;

/// Stamps exactly representable at any offset (a spacing of 2^-10 s): the filters'
/// arithmetic gives bit-identical estimates at T0 = 1.8e9 s and at T0 = 0 (the centred
/// times of the fit and the Kalman filter's dt are exact differences).
constexpr double kEpochExactStamps = 0.0;

/// Long runs (1e7 samples of a 1 Hz sine, spaced 2^-10 s, 1 ms, or 1 ms +-40%): the
/// worst error over the last 1e5 samples over that of samples 1e4..1.1e5 (measured 0.98
/// to 1.03, the irregular runs' own spread; bound 1.1), and the distance of the
/// long-running estimate from a bank started 2e5 samples before the end, relative to
/// 1 + |qdd|: bit-identical for the window filters, at most 1.4e-12 for the Kalman
/// filters (their covariance and state reach the same values by another rounding
/// path); bound 1e-11, margin 7. Where the stamps' rounding lets the bank reuse what it
/// computed earlier (a steady rate), the bounds below apply instead.
constexpr double kLongRunDrift = 1.1;
constexpr double kLongRunFresh = 1e-11;

/// The bank keeps its weights while every sample of the window stays within this
/// distance [s] of where the last fit had it, and the Kalman filter its F and Q while dt
/// stays within it of the dt they were computed for (differentiation.hpp, mirrored
/// here): two banks that computed them at different times may then differ by the
/// effect of moving every sample by up to twice this much.
constexpr double kWeightsReuseSpacing = 1e-10;

/// For a Kalman filter at spacing h, that is a time scale off by up to
/// 2 kWeightsReuseSpacing / h between two banks, and a second derivative off by twice
/// that, relatively (measured 4.1e-10 at 1 ms, against 4e-7).
inline double kalmanReuseBound(double h) { return 4.0 * kWeightsReuseSpacing / h; }

}  // namespace bounds
}  // namespace jle_test
