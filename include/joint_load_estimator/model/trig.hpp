// sin and cos of one angle together, for the forward pass's joint rotations: in double
// a branch-free Cody-Waite reduction and the minimax kernels of fdlibm (Sun's freely
// distributable libm, as musl carries them), about 4 times cheaper than the C library's
// sin and cos, within 1 ulp of the exact value for |q| <= kFastTrigLimit; any other
// scalar type, and larger angles, go to std::sin and std::cos. sinCosArray and
// sinCosMany do many angles, in double 8 at a time in vector registers (the same
// operations in each lane: the same bits as sinCos; src/model/trig.cpp).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

// Forced inlining (GCC and Clang): the forward pass's per-segment steps
// (kinematics.hpp) and the kernels below.
#if defined(__GNUC__)
#define JLE_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define JLE_ALWAYS_INLINE inline
#endif

namespace jle {

/// Largest |q| [rad] the fast path takes (the reduction by pi/2 in two parts is exact
/// to 1e-20 rad up to there).
constexpr double kFastTrigLimit = 1e6;

namespace detail {

// sin(x + y) and cos(x + y) for |x| <= pi/4, y the tail of the reduced argument
// (fdlibm's __kernel_sin and __kernel_cos, musl's arrangement).
// Always inlined: src/model/trig.cpp instantiates it on vectors in functions compiled
// for different instruction sets, each of which must have its own copy.
template <typename T>
JLE_ALWAYS_INLINE void kernelSinCos(T x, T y, T& s, T& c) {
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  const T z = x * x;
  const T w = z * z;
  const T rs = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
  const T v = z * x;
  s = x - ((z * (0.5 * y - v * rs) - y) - v * S1);
  const T rc = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
  const T hz = 0.5 * z;
  const T one_minus = 1.0 - hz;
  c = one_minus + (((1.0 - one_minus) - hz) + (z * rc - x * y));
}

// The reduction's constants (sinCos<double>).
constexpr double kInvPio2 = 6.36619772367581382433e-01;
constexpr double kPio2_1 = 1.57079632673412561417e+00;   // first 33 bits of pi/2
constexpr double kPio2_1t = 6.07710050650619224932e-11;  // pi/2 - kPio2_1
constexpr double kToInt = 6755399441055744.0;  // 1.5 * 2^52: adding it rounds to an integer

}  // namespace detail

/// s = sin(q), c = cos(q).
template <typename Scalar>
inline void sinCos(Scalar q, Scalar& s, Scalar& c) {
  using std::cos;
  using std::sin;
  s = sin(q);
  c = cos(q);
}

template <>
inline void sinCos<double>(double q, double& s, double& c) {
  if (!(std::abs(q) <= kFastTrigLimit)) {  // large, or not finite
    s = std::sin(q);
    c = std::cos(q);
    return;
  }
  // q = n pi/2 + r, |r| <= pi/4 (a little more at a rounding of n), r = y0 + y1.
  using namespace detail;
  const double n = (q * kInvPio2 + kToInt) - kToInt;
  const double r = q - n * kPio2_1;  // exact: n has at most 20 bits
  const double w = n * kPio2_1t;
  const double y0 = r - w;
  const double y1 = (r - y0) - w;
  double ks, kc;
  detail::kernelSinCos(y0, y1, ks, kc);
  // The quadrant n mod 4 swaps the kernels (odd n) and flips their signs, on the bits so
  // that no branch depends on the angle.
  const std::uint64_t quadrant = static_cast<std::uint64_t>(static_cast<std::int64_t>(n));
  const std::uint64_t swap = 0 - (quadrant & 1);
  std::uint64_t bs, bc;
  std::memcpy(&bs, &ks, sizeof bs);
  std::memcpy(&bc, &kc, sizeof bc);
  std::uint64_t out_s = (bs & ~swap) | (bc & swap);
  std::uint64_t out_c = (bc & ~swap) | (bs & swap);
  out_s ^= (quadrant & 2) << 62;
  out_c ^= ((quadrant + 1) & 2) << 62;
  std::memcpy(&s, &out_s, sizeof s);
  std::memcpy(&c, &out_c, sizeof c);
}

/// Which vector instructions sinCosArray<double> uses: chosen once, at its first call,
/// as the widest this CPU has (x86-64: AVX-512F, AVX2, else SSE2; elsewhere the
/// compiler's generic vectors). Each takes the angles 8 at a time, the same operations
/// in each lane, so each gives the bits of sinCos.
enum class TrigPath : std::uint8_t { kGeneric, kAvx2, kAvx512 };

/// The path sinCosArray<double> takes on this CPU.
TrigPath trigPath();
/// Whether this CPU can take `path` (kGeneric: always).
bool trigPathSupported(TrigPath path);
/// sinCosArray<double> through `path` (which trigPathSupported must allow), for tests
/// and benchmarks of each path.
void sinCosArray(TrigPath path, int count, const double* q, double* s, double* c);

/// s[j] = sin(q[j]), c[j] = cos(q[j]), j = 0..count-1.
template <typename Scalar>
inline void sinCosArray(int count, const Scalar* q, Scalar* s, Scalar* c) {
  for (int j = 0; j < count; ++j) sinCos(q[j], s[j], c[j]);
}

/// In double: sinCos's bits, 8 angles at a time in vector registers (trigPath(); in
/// the core library, so the instructions depend on the CPU, not on a client's flags).
/// A group of 8 with a large or non-finite angle is redone with sinCos one by one.
template <>
void sinCosArray<double>(int count, const double* q, double* s, double* c);

/// sinCos of count angles: s[index(j)] = sin(q[index(j)]), likewise c, j = 0..count-1.
template <typename Scalar, typename Index>
inline void sinCosMany(int count, Index index, const Scalar* q, Scalar* s, Scalar* c) {
  for (int j = 0; j < count; ++j) sinCos(q[index(j)], s[index(j)], c[index(j)]);
}

/// In double: gathered into blocks for sinCosArray<double>.
template <typename Index>
inline void sinCosMany(int count, Index index, const double* q, double* s, double* c) {
  constexpr int kBlock = 64;
  double qb[kBlock], sb[kBlock], cb[kBlock];
  for (int j0 = 0; j0 < count; j0 += kBlock) {
    const int m = count - j0 < kBlock ? count - j0 : kBlock;
    for (int j = 0; j < m; ++j) qb[j] = q[index(j0 + j)];
    sinCosArray<double>(m, qb, sb, cb);
    for (int j = 0; j < m; ++j) {
      const int i = index(j0 + j);
      s[i] = sb[j];
      c[i] = cb[j];
    }
  }
}

}  // namespace jle
