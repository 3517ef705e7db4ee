// A quad-precision scalar (GCC's __float128, libquadmath) that Eigen and the core's
// templates accept: the reference of bench/stability.cpp. The value is wrapped in a
// class so that the core's unqualified math calls (`using std::sin; sin(x)`) find the
// overloads below by argument-dependent lookup, which a built-in type would not get.
#pragma once

#include <Eigen/Core>

#include <quadmath.h>

#include <limits>
#include <string>

namespace jle_bench {

/// IEEE binary128: 113-bit significand, epsilon 1.9e-34.
struct Quad {
  __float128 v = 0;
  Quad() = default;
  // Implicit from the built-in types, as a float or a double is: the core writes
  // Scalar(0), Scalar(64) and mixes them with Scalar values.
  Quad(__float128 x) : v(x) {}   // NOLINT(runtime/explicit)
  Quad(double x) : v(x) {}       // NOLINT(runtime/explicit)
  Quad(long double x) : v(x) {}  // NOLINT(runtime/explicit)
  Quad(float x) : v(x) {}        // NOLINT(runtime/explicit)
  Quad(int x) : v(x) {}          // NOLINT(runtime/explicit)
  explicit operator double() const { return static_cast<double>(v); }
  explicit operator long double() const { return static_cast<long double>(v); }
  explicit operator float() const { return static_cast<float>(v); }
  Quad& operator+=(Quad o) {
    v += o.v;
    return *this;
  }
  Quad& operator-=(Quad o) {
    v -= o.v;
    return *this;
  }
  Quad& operator*=(Quad o) {
    v *= o.v;
    return *this;
  }
  Quad& operator/=(Quad o) {
    v /= o.v;
    return *this;
  }
};

inline Quad operator+(Quad a, Quad b) { return Quad(a.v + b.v); }
inline Quad operator-(Quad a, Quad b) { return Quad(a.v - b.v); }
inline Quad operator*(Quad a, Quad b) { return Quad(a.v * b.v); }
inline Quad operator/(Quad a, Quad b) { return Quad(a.v / b.v); }
inline Quad operator-(Quad a) { return Quad(-a.v); }
inline Quad operator+(Quad a) { return a; }
inline bool operator==(Quad a, Quad b) { return a.v == b.v; }
inline bool operator!=(Quad a, Quad b) { return a.v != b.v; }
inline bool operator<(Quad a, Quad b) { return a.v < b.v; }
inline bool operator<=(Quad a, Quad b) { return a.v <= b.v; }
inline bool operator>(Quad a, Quad b) { return a.v > b.v; }
inline bool operator>=(Quad a, Quad b) { return a.v >= b.v; }

inline Quad sqrt(Quad a) { return Quad(sqrtq(a.v)); }
inline Quad sin(Quad a) { return Quad(sinq(a.v)); }
inline Quad cos(Quad a) { return Quad(cosq(a.v)); }
inline Quad abs(Quad a) { return Quad(fabsq(a.v)); }
inline Quad fabs(Quad a) { return Quad(fabsq(a.v)); }
inline Quad exp(Quad a) { return Quad(expq(a.v)); }
inline Quad log(Quad a) { return Quad(logq(a.v)); }
inline Quad pow(Quad a, Quad b) { return Quad(powq(a.v, b.v)); }
inline Quad atan2(Quad a, Quad b) { return Quad(atan2q(a.v, b.v)); }
inline Quad floor(Quad a) { return Quad(floorq(a.v)); }
inline Quad ceil(Quad a) { return Quad(ceilq(a.v)); }
inline bool isfinite(Quad a) { return finiteq(a.v) != 0; }
inline bool isnan(Quad a) { return isnanq(a.v) != 0; }
inline bool isinf(Quad a) { return isinfq(a.v) != 0; }
inline Quad real(Quad a) { return a; }
inline Quad imag(Quad) { return Quad(0); }
inline Quad conj(Quad a) { return a; }
inline Quad abs2(Quad a) { return a * a; }

inline std::string toString(Quad a) {
  char buf[64];
  quadmath_snprintf(buf, sizeof buf, "%.36Qg", a.v);
  return buf;
}

}  // namespace jle_bench

namespace std {
template <>
class numeric_limits<jle_bench::Quad> {
 public:
  static constexpr bool is_specialized = true;
  static constexpr bool is_signed = true;
  static constexpr bool is_integer = false;
  static constexpr bool is_exact = false;
  static constexpr bool has_infinity = true;
  static constexpr bool has_quiet_NaN = true;
  static constexpr int digits = FLT128_MANT_DIG;
  static constexpr int digits10 = FLT128_DIG;
  static jle_bench::Quad epsilon() { return jle_bench::Quad(FLT128_EPSILON); }
  static jle_bench::Quad min() { return jle_bench::Quad(FLT128_MIN); }
  static jle_bench::Quad max() { return jle_bench::Quad(FLT128_MAX); }
  static jle_bench::Quad lowest() { return jle_bench::Quad(-FLT128_MAX); }
  static jle_bench::Quad infinity() { return jle_bench::Quad(__builtin_huge_valq()); }
  static jle_bench::Quad quiet_NaN() { return jle_bench::Quad(nanq("")); }
};
}  // namespace std

namespace Eigen {
template <>
struct NumTraits<jle_bench::Quad> : GenericNumTraits<jle_bench::Quad> {
  using Real = jle_bench::Quad;
  using NonInteger = jle_bench::Quad;
  using Nested = jle_bench::Quad;
  using Literal = jle_bench::Quad;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 2,
    AddCost = 20,
    MulCost = 40,
  };
  static Real epsilon() { return Real(FLT128_EPSILON); }
  static Real dummy_precision() { return Real(1e-30); }
  static Real highest() { return Real(FLT128_MAX); }
  static Real lowest() { return Real(-FLT128_MAX); }
  static int digits10() { return FLT128_DIG; }
};
}  // namespace Eigen
