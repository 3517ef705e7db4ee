// sinCosArray<double>: the reduction and kernels of sinCos<double> (trig.hpp) on 8, 4 or
// 2 angles at once in GCC's vector extensions, compiled three times on x86-64 (AVX-512F, AVX2,
// the generic SSE2 lowering) and chosen at run time by the CPU. This file is compiled
// with -ffp-contract=off: a fused multiply-add would round differently from sinCos.
#include <joint_load_estimator/model/trig.hpp>

#include <cstdint>
#include <cstring>

namespace jle {
namespace {

typedef double V8 __attribute__((vector_size(64)));
typedef std::int64_t I8 __attribute__((vector_size(64)));
typedef double V4 __attribute__((vector_size(32)));
typedef std::int64_t I4 __attribute__((vector_size(32)));
typedef double V2 __attribute__((vector_size(16)));
typedef std::int64_t I2 __attribute__((vector_size(16)));

// sinCos<double> of the sizeof(V) / 8 angles from q into s and c, for |q| <=
// kFastTrigLimit in every lane. The quadrant n mod 4 is read from the low bits of
// n + kToInt, whose unit is the last place.
template <typename V, typename I>
JLE_ALWAYS_INLINE void lanes(const double* q, double* s, double* c) {
  using namespace detail;
  V x;
  std::memcpy(&x, q, sizeof x);
  const V shifted = x * kInvPio2 + kToInt;
  const V n = shifted - kToInt;
  const V r = x - n * kPio2_1;
  const V w = n * kPio2_1t;
  const V y0 = r - w;
  const V y1 = (r - y0) - w;
  V ks, kc;
  kernelSinCos(y0, y1, ks, kc);
  I quadrant, bs, bc;
  std::memcpy(&quadrant, &shifted, sizeof quadrant);
  std::memcpy(&bs, &ks, sizeof bs);
  std::memcpy(&bc, &kc, sizeof bc);
  const I swap = -(quadrant & 1);
  I out_s = (bs & ~swap) | (bc & swap);
  I out_c = (bc & ~swap) | (bs & swap);
  out_s ^= (quadrant & 2) << 62;
  out_c ^= ((quadrant + 1) & 2) << 62;
  std::memcpy(s, &out_s, sizeof out_s);
  std::memcpy(c, &out_c, sizeof out_c);
}

// The angles q[0..L) as lanes(), or one by one through sinCos where one of them is
// large or not finite.
template <typename V, typename I>
JLE_ALWAYS_INLINE void group(const double* q, double* s, double* c) {
  constexpr int kCount = sizeof(V) / sizeof(double);
  bool fast = true;
  for (int l = 0; l < kCount; ++l) fast &= std::abs(q[l]) <= kFastTrigLimit;
  if (fast) {
    lanes<V, I>(q, s, c);
  } else {
    for (int l = 0; l < kCount; ++l) sinCos(q[l], s[l], c[l]);
  }
}

// The whole array: groups of 8, then at most one of 4, one of 2 and one angle alone.
JLE_ALWAYS_INLINE void groups(int count, const double* q, double* s, double* c) {
  int j = 0;
  for (; j + 8 <= count; j += 8) group<V8, I8>(q + j, s + j, c + j);
  if (j + 4 <= count) {
    group<V4, I4>(q + j, s + j, c + j);
    j += 4;
  }
  if (j + 2 <= count) {
    group<V2, I2>(q + j, s + j, c + j);
    j += 2;
  }
  if (j < count) sinCos(q[j], s[j], c[j]);
}

void generic(int count, const double* q, double* s, double* c) { groups(count, q, s, c); }

#if defined(__x86_64__) && defined(__GNUC__)
#define JLE_TRIG_X86 1
__attribute__((target("avx2"))) void avx2(int count, const double* q, double* s, double* c) {
  groups(count, q, s, c);
}
__attribute__((target("avx512f"))) void avx512(int count, const double* q, double* s, double* c) {
  groups(count, q, s, c);
}
#endif

using Path = void (*)(int, const double*, double*, double*);

Path pathFunction(TrigPath path) {
#ifdef JLE_TRIG_X86
  if (path == TrigPath::kAvx512) return avx512;
  if (path == TrigPath::kAvx2) return avx2;
#endif
  (void)path;
  return generic;
}

TrigPath choosePath() {
#ifdef JLE_TRIG_X86
  __builtin_cpu_init();  // in case the first call comes from another library's constructor
#endif
  if (trigPathSupported(TrigPath::kAvx512)) return TrigPath::kAvx512;
  if (trigPathSupported(TrigPath::kAvx2)) return TrigPath::kAvx2;
  return TrigPath::kGeneric;
}

}  // namespace

bool trigPathSupported(TrigPath path) {
  switch (path) {
    case TrigPath::kGeneric: return true;
#ifdef JLE_TRIG_X86
    case TrigPath::kAvx2: return __builtin_cpu_supports("avx2");
    case TrigPath::kAvx512: return __builtin_cpu_supports("avx512f");
#endif
    default: return false;
  }
}

TrigPath trigPath() {
  static const TrigPath chosen = choosePath();
  return chosen;
}

void sinCosArray(TrigPath path, int count, const double* q, double* s, double* c) {
  pathFunction(path)(count, q, s, c);
}

template <>
void sinCosArray<double>(int count, const double* q, double* s, double* c) {
  static const Path chosen = pathFunction(trigPath());
  chosen(count, q, s, c);
}

}  // namespace jle
