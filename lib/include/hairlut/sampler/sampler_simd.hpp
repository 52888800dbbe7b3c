// hairlut sampler, four lanes of arithmetic: what the fixed-dimension views (sampler_fixed.hpp)
// and the fiber evaluator (sampler_fiber.hpp) use to combine four values in one operation.
//
// Header-only and dependency-free (C++17 standard library only). detail::Vec4<R> holds four
// values of the arithmetic type R: one SSE2 register for float, two for double, on every x86-64
// target (SSE2 is the baseline ISA: no -march needed); elsewhere, or with HAIRLUT_SAMPLER_NO_SIMD
// defined, an array with the same operations in the same order, so that both give the same bits.
#pragma once

#include <cmath>
#include <cstddef>
#include <type_traits>

// The per-axis tap computation is forced inline: a lookup is a handful of them and the call
// overhead is of the same order as their work.
// HAIRLUT_SAMPLER_LAMBDA_INLINE does the same for a lambda (after its parameter list).
#if defined(__GNUC__) || defined(__clang__)
#define HAIRLUT_SAMPLER_INLINE __attribute__((always_inline)) inline
#define HAIRLUT_SAMPLER_LAMBDA_INLINE __attribute__((always_inline))
#define HAIRLUT_SAMPLER_NOINLINE __attribute__((noinline))
#else
#define HAIRLUT_SAMPLER_INLINE inline
#define HAIRLUT_SAMPLER_LAMBDA_INLINE
#define HAIRLUT_SAMPLER_NOINLINE
#endif

// SSE2 (every x86-64 target) combines values in registers; elsewhere, or with
// HAIRLUT_SAMPLER_NO_SIMD defined, the same operations run one value at a time. The results are
// the same (IEEE operations in the same order).
#if !defined(HAIRLUT_SAMPLER_NO_SIMD) && (defined(__SSE2__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2))
#define HAIRLUT_SAMPLER_SSE2 1
#include <emmintrin.h>
#else
#define HAIRLUT_SAMPLER_SSE2 0
#endif

namespace hairlut {
namespace sampler {
namespace detail {

/// Four multipliers below 2³² (the strides of up to four axes) for Vec4::split_offset, in the
/// layouts its SSE2 forms multiply by (pmuludq multiplies the low 32 bits of each 64-bit lane).
struct Strides4 {
  std::size_t s[4] = {0, 0, 0, 0};
#if HAIRLUT_SAMPLER_SSE2
  __m128i m01{}, m23{}, m02{}, m13{};  // (s₀, s₁), (s₂, s₃), (s₀, s₂), (s₁, s₃) as 64-bit lanes
#endif
  Strides4() = default;
  /// Whether every s_k < 2³² (what split_offset needs).
  static bool fits(const std::size_t* s) {
    for (int k = 0; k < 4; ++k)
      if (static_cast<unsigned long long>(s[k]) > 0xffffffffull) return false;
    return true;
  }
  /// Σ i_k · s_k (i_k ≥ 0).
  std::size_t dot(const int* i) const {
    return static_cast<std::size_t>(i[0]) * s[0] + static_cast<std::size_t>(i[1]) * s[1] + static_cast<std::size_t>(i[2]) * s[2] + static_cast<std::size_t>(i[3]) * s[3];
  }
  explicit Strides4(const std::size_t* m) {
    for (int k = 0; k < 4; ++k) s[k] = m[k];
#if HAIRLUT_SAMPLER_SSE2
    const auto q = [](std::size_t a, std::size_t b) { return _mm_set_epi64x(static_cast<long long>(b & 0xffffffffu), static_cast<long long>(a & 0xffffffffu)); };
    m01 = q(m[0], m[1]), m23 = q(m[2], m[3]), m02 = q(m[0], m[2]), m13 = q(m[1], m[3]);
#endif
  }
};

/// Four values of R in one or two SSE2 registers (float: one __m128; double: two __m128d), or an
/// array where SSE2 is not available (or Simd is false): the same operations in the same order
/// either way.
template <class R, bool Simd = HAIRLUT_SAMPLER_SSE2 != 0>
struct Vec4 {
  R v[4];
  static HAIRLUT_SAMPLER_INLINE Vec4 load(const R* p) { return {{p[0], p[1], p[2], p[3]}}; }
  /// Four consecutive stored values converted to R.
  template <class T>
  static HAIRLUT_SAMPLER_INLINE Vec4 load_from(const T* p) {
    return {{static_cast<R>(p[0]), static_cast<R>(p[1]), static_cast<R>(p[2]), static_cast<R>(p[3])}};
  }
  /// p[off[0]], …, p[off[3]] converted to R.
  template <class T>
  static HAIRLUT_SAMPLER_INLINE Vec4 gather(const T* p, const std::size_t* off) {
    return {{static_cast<R>(p[off[0]]), static_cast<R>(p[off[1]]), static_cast<R>(p[off[2]]), static_cast<R>(p[off[3]])}};
  }
  static HAIRLUT_SAMPLER_INLINE Vec4 all(R x) { return {{x, x, x, x}}; }
  static HAIRLUT_SAMPLER_INLINE Vec4 set(R a, R b, R c, R d) { return {{a, b, c, d}}; }
  /// Lane L in every lane.
  template <int L>
  HAIRLUT_SAMPLER_INLINE Vec4 lane() const {
    return all(v[L]);
  }
  friend HAIRLUT_SAMPLER_INLINE Vec4 operator+(const Vec4& a, const Vec4& b) { return {{a.v[0] + b.v[0], a.v[1] + b.v[1], a.v[2] + b.v[2], a.v[3] + b.v[3]}}; }
  friend HAIRLUT_SAMPLER_INLINE Vec4 operator-(const Vec4& a, const Vec4& b) { return {{a.v[0] - b.v[0], a.v[1] - b.v[1], a.v[2] - b.v[2], a.v[3] - b.v[3]}}; }
  /// a < b ? a : b and a > b ? a : b per lane (a NaN gives b).
  static HAIRLUT_SAMPLER_INLINE Vec4 min(const Vec4& a, const Vec4& b) {
    Vec4 r;
    for (int k = 0; k < 4; ++k) r.v[k] = a.v[k] < b.v[k] ? a.v[k] : b.v[k];
    return r;
  }
  static HAIRLUT_SAMPLER_INLINE Vec4 max(const Vec4& a, const Vec4& b) {
    Vec4 r;
    for (int k = 0; k < 4; ++k) r.v[k] = a.v[k] > b.v[k] ? a.v[k] : b.v[k];
    return r;
  }
  /// Bit k set where a_k > b_k.
  static HAIRLUT_SAMPLER_INLINE int greater(const Vec4& a, const Vec4& b) {
    return (a.v[0] > b.v[0] ? 1 : 0) | (a.v[1] > b.v[1] ? 2 : 0) | (a.v[2] > b.v[2] ? 4 : 0) | (a.v[3] > b.v[3] ? 8 : 0);
  }
  /// Whether a lane is NaN.
  static HAIRLUT_SAMPLER_INLINE bool unordered(const Vec4& a) { return !(a.v[0] == a.v[0]) || !(a.v[1] == a.v[1]) || !(a.v[2] == a.v[2]) || !(a.v[3] == a.v[3]); }
  /// i_k = static_cast<int>(v_k) (truncation; v_k within int's range), and returns v_k − i_k.
  HAIRLUT_SAMPLER_INLINE Vec4 split(int* i) const {
    Vec4 r;
    for (int k = 0; k < 4; ++k) i[k] = static_cast<int>(v[k]), r.v[k] = v[k] - static_cast<R>(i[k]);
    return r;
  }
  /// split(i) for v_k ≥ 0, and o = Σ i_k · m.s_k (in registers where SSE2 is, not through i).
  HAIRLUT_SAMPLER_INLINE Vec4 split_offset(int* i, const Strides4& m, std::size_t& o) const {
    const Vec4 r = split(i);
    o = m.dot(i);
    return r;
  }
  /// |v| per lane.
  HAIRLUT_SAMPLER_INLINE Vec4 abs() const { return {{std::fabs(v[0]), std::fabs(v[1]), std::fabs(v[2]), std::fabs(v[3])}}; }
  /// √v per lane (correctly rounded, as std::sqrt).
  HAIRLUT_SAMPLER_INLINE Vec4 sqrt() const { return {{std::sqrt(v[0]), std::sqrt(v[1]), std::sqrt(v[2]), std::sqrt(v[3])}}; }
  /// x_k < 0 ? a_k : b_k per lane.
  static HAIRLUT_SAMPLER_INLINE Vec4 if_negative(const Vec4& x, const Vec4& a, const Vec4& b) {
    Vec4 r;
    for (int k = 0; k < 4; ++k) r.v[k] = x.v[k] < R(0) ? a.v[k] : b.v[k];
    return r;
  }
  friend HAIRLUT_SAMPLER_INLINE Vec4 operator*(const Vec4& a, const Vec4& b) { return {{a.v[0] * b.v[0], a.v[1] * b.v[1], a.v[2] * b.v[2], a.v[3] * b.v[3]}}; }
  /// max(v, 0) per lane; NaN stays NaN.
  HAIRLUT_SAMPLER_INLINE Vec4 nonnegative() const {
    Vec4 r;
    for (int k = 0; k < 4; ++k) r.v[k] = v[k] < R(0) ? R(0) : v[k];
    return r;
  }
  HAIRLUT_SAMPLER_INLINE R lane0() const { return v[0]; }
  /// (x₀ + x₂) + (x₁ + x₃).
  HAIRLUT_SAMPLER_INLINE R sum() const { return (v[0] + v[2]) + (v[1] + v[3]); }
  /// (Σ a, Σ b, Σ c, 0), each sum as (x₀ + x₂) + (x₁ + x₃).
  static HAIRLUT_SAMPLER_INLINE Vec4 sums(const Vec4& a, const Vec4& b, const Vec4& c) {
    return {{(a.v[0] + a.v[2]) + (a.v[1] + a.v[3]), (b.v[0] + b.v[2]) + (b.v[1] + b.v[3]), (c.v[0] + c.v[2]) + (c.v[1] + c.v[3]), R(0)}};
  }
  HAIRLUT_SAMPLER_INLINE void store3(R* out) const { out[0] = v[0], out[1] = v[1], out[2] = v[2]; }
  /// The four lanes to out[0 … 3].
  HAIRLUT_SAMPLER_INLINE void store(R* out) const { out[0] = v[0], out[1] = v[1], out[2] = v[2], out[3] = v[3]; }
};
#if HAIRLUT_SAMPLER_SSE2
template <>
struct Vec4<float, true> {
  __m128 v;
  static HAIRLUT_SAMPLER_INLINE Vec4 load(const float* p) { return {_mm_loadu_ps(p)}; }
  template <class T>
  static HAIRLUT_SAMPLER_INLINE Vec4 load_from(const T* p) {
    if constexpr (std::is_same_v<T, float>) return {_mm_loadu_ps(p)};
    else return {_mm_set_ps(static_cast<float>(p[3]), static_cast<float>(p[2]), static_cast<float>(p[1]), static_cast<float>(p[0]))};
  }
  template <class T>
  static HAIRLUT_SAMPLER_INLINE Vec4 gather(const T* p, const std::size_t* off) {
    return {_mm_set_ps(static_cast<float>(p[off[3]]), static_cast<float>(p[off[2]]), static_cast<float>(p[off[1]]), static_cast<float>(p[off[0]]))};
  }
  static HAIRLUT_SAMPLER_INLINE Vec4 all(float x) { return {_mm_set1_ps(x)}; }
  static HAIRLUT_SAMPLER_INLINE Vec4 set(float a, float b, float c, float d) { return {_mm_set_ps(d, c, b, a)}; }
  template <int L>
  HAIRLUT_SAMPLER_INLINE Vec4 lane() const {
    return {_mm_shuffle_ps(v, v, L * 0x55)};
  }
  friend HAIRLUT_SAMPLER_INLINE Vec4 operator+(const Vec4& a, const Vec4& b) { return {_mm_add_ps(a.v, b.v)}; }
  friend HAIRLUT_SAMPLER_INLINE Vec4 operator-(const Vec4& a, const Vec4& b) { return {_mm_sub_ps(a.v, b.v)}; }
  // minps/maxps return their second operand where either is NaN (and where equal).
  static HAIRLUT_SAMPLER_INLINE Vec4 min(const Vec4& a, const Vec4& b) { return {_mm_min_ps(a.v, b.v)}; }
  static HAIRLUT_SAMPLER_INLINE Vec4 max(const Vec4& a, const Vec4& b) { return {_mm_max_ps(a.v, b.v)}; }
  static HAIRLUT_SAMPLER_INLINE int greater(const Vec4& a, const Vec4& b) { return _mm_movemask_ps(_mm_cmpgt_ps(a.v, b.v)); }
  static HAIRLUT_SAMPLER_INLINE bool unordered(const Vec4& a) { return _mm_movemask_ps(_mm_cmpunord_ps(a.v, a.v)) != 0; }
  HAIRLUT_SAMPLER_INLINE Vec4 split(int* i) const {
    const __m128i q = _mm_cvttps_epi32(v);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(i), q);
    return {_mm_sub_ps(v, _mm_cvtepi32_ps(q))};
  }
  HAIRLUT_SAMPLER_INLINE Vec4 split_offset(int* i, const Strides4& m, std::size_t& o) const {
    const __m128i q = _mm_cvttps_epi32(v);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(i), q);
    // (i₀ s₀ + i₂ s₂, i₁ s₁ + i₃ s₃) in 64-bit lanes, then their sum: exact integers.
#if defined(__x86_64__) || defined(_M_X64)
    const __m128i p = _mm_add_epi64(_mm_mul_epu32(q, m.m02), _mm_mul_epu32(_mm_srli_epi64(q, 32), m.m13));
    o = static_cast<std::size_t>(_mm_cvtsi128_si64(_mm_add_epi64(p, _mm_unpackhi_epi64(p, p))));
#else
    o = m.dot(i);
#endif
    return {_mm_sub_ps(v, _mm_cvtepi32_ps(q))};
  }
  HAIRLUT_SAMPLER_INLINE Vec4 abs() const { return {_mm_and_ps(v, _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff)))}; }
  HAIRLUT_SAMPLER_INLINE Vec4 sqrt() const { return {_mm_sqrt_ps(v)}; }
  static HAIRLUT_SAMPLER_INLINE Vec4 if_negative(const Vec4& x, const Vec4& a, const Vec4& b) {
    const __m128 m = _mm_cmplt_ps(x.v, _mm_setzero_ps());
    return {_mm_or_ps(_mm_and_ps(m, a.v), _mm_andnot_ps(m, b.v))};
  }
  friend HAIRLUT_SAMPLER_INLINE Vec4 operator*(const Vec4& a, const Vec4& b) { return {_mm_mul_ps(a.v, b.v)}; }
  // maxps returns its second operand where either is NaN.
  HAIRLUT_SAMPLER_INLINE Vec4 nonnegative() const { return {_mm_max_ps(_mm_setzero_ps(), v)}; }
  HAIRLUT_SAMPLER_INLINE float lane0() const { return _mm_cvtss_f32(v); }
  HAIRLUT_SAMPLER_INLINE float sum() const {
    const __m128 h = _mm_add_ps(v, _mm_movehl_ps(v, v));  // (x₀ + x₂, x₁ + x₃, …)
    return _mm_cvtss_f32(_mm_add_ss(h, _mm_shuffle_ps(h, h, 1)));
  }
  static HAIRLUT_SAMPLER_INLINE Vec4 sums(const Vec4& a, const Vec4& b, const Vec4& c) {
    // The transpose of (a, b, c, 0): x_k = (a_k, b_k, c_k, 0).
    const __m128 z = _mm_setzero_ps();
    const __m128 ab01 = _mm_unpacklo_ps(a.v, b.v), ab23 = _mm_unpackhi_ps(a.v, b.v);
    const __m128 c01 = _mm_unpacklo_ps(c.v, z), c23 = _mm_unpackhi_ps(c.v, z);
    const __m128 x0 = _mm_movelh_ps(ab01, c01), x1 = _mm_movehl_ps(c01, ab01);
    const __m128 x2 = _mm_movelh_ps(ab23, c23), x3 = _mm_movehl_ps(c23, ab23);
    return {_mm_add_ps(_mm_add_ps(x0, x2), _mm_add_ps(x1, x3))};
  }
  HAIRLUT_SAMPLER_INLINE void store(float* out) const { _mm_storeu_ps(out, v); }
  HAIRLUT_SAMPLER_INLINE void store3(float* out) const {
    alignas(16) float t[4];
    _mm_store_ps(t, v);
    out[0] = t[0], out[1] = t[1], out[2] = t[2];
  }
};
template <>
struct Vec4<double, true> {
  __m128d lo, hi;
  static HAIRLUT_SAMPLER_INLINE Vec4 load(const double* p) { return {_mm_loadu_pd(p), _mm_loadu_pd(p + 2)}; }
  template <class T>
  static HAIRLUT_SAMPLER_INLINE Vec4 load_from(const T* p) {
    if constexpr (std::is_same_v<T, double>) {
      return {_mm_loadu_pd(p), _mm_loadu_pd(p + 2)};
    } else if constexpr (std::is_same_v<T, float>) {
      // Two pairs, each a 64-bit load and one cvtps2pd. The load goes through __m128i, which may
      // alias anything (a load through a double* of float storage breaks the aliasing rules, and
      // GCC then moved it ahead of the stores it reads).
      return {_mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)))),
              _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p + 2))))};
    } else {
      return {_mm_set_pd(static_cast<double>(p[1]), static_cast<double>(p[0])), _mm_set_pd(static_cast<double>(p[3]), static_cast<double>(p[2]))};
    }
  }
  template <class T>
  static HAIRLUT_SAMPLER_INLINE Vec4 gather(const T* p, const std::size_t* off) {
    return {_mm_set_pd(static_cast<double>(p[off[1]]), static_cast<double>(p[off[0]])), _mm_set_pd(static_cast<double>(p[off[3]]), static_cast<double>(p[off[2]]))};
  }
  static HAIRLUT_SAMPLER_INLINE Vec4 all(double x) { return {_mm_set1_pd(x), _mm_set1_pd(x)}; }
  static HAIRLUT_SAMPLER_INLINE Vec4 set(double a, double b, double c, double d) { return {_mm_set_pd(b, a), _mm_set_pd(d, c)}; }
  template <int L>
  HAIRLUT_SAMPLER_INLINE Vec4 lane() const {
    const __m128d h = L < 2 ? lo : hi;
    const __m128d b = L % 2 == 0 ? _mm_unpacklo_pd(h, h) : _mm_unpackhi_pd(h, h);
    return {b, b};
  }
  friend HAIRLUT_SAMPLER_INLINE Vec4 operator+(const Vec4& a, const Vec4& b) { return {_mm_add_pd(a.lo, b.lo), _mm_add_pd(a.hi, b.hi)}; }
  friend HAIRLUT_SAMPLER_INLINE Vec4 operator-(const Vec4& a, const Vec4& b) { return {_mm_sub_pd(a.lo, b.lo), _mm_sub_pd(a.hi, b.hi)}; }
  static HAIRLUT_SAMPLER_INLINE Vec4 min(const Vec4& a, const Vec4& b) { return {_mm_min_pd(a.lo, b.lo), _mm_min_pd(a.hi, b.hi)}; }
  static HAIRLUT_SAMPLER_INLINE Vec4 max(const Vec4& a, const Vec4& b) { return {_mm_max_pd(a.lo, b.lo), _mm_max_pd(a.hi, b.hi)}; }
  static HAIRLUT_SAMPLER_INLINE int greater(const Vec4& a, const Vec4& b) {
    return _mm_movemask_pd(_mm_cmpgt_pd(a.lo, b.lo)) | (_mm_movemask_pd(_mm_cmpgt_pd(a.hi, b.hi)) << 2);
  }
  static HAIRLUT_SAMPLER_INLINE bool unordered(const Vec4& a) {
    return _mm_movemask_pd(_mm_or_pd(_mm_cmpunord_pd(a.lo, a.lo), _mm_cmpunord_pd(a.hi, a.hi))) != 0;
  }
  HAIRLUT_SAMPLER_INLINE Vec4 split(int* i) const {
    const __m128i ql = _mm_cvttpd_epi32(lo), qh = _mm_cvttpd_epi32(hi);
    _mm_storel_epi64(reinterpret_cast<__m128i*>(i), ql);
    _mm_storel_epi64(reinterpret_cast<__m128i*>(i + 2), qh);
    return {_mm_sub_pd(lo, _mm_cvtepi32_pd(ql)), _mm_sub_pd(hi, _mm_cvtepi32_pd(qh))};
  }
  HAIRLUT_SAMPLER_INLINE Vec4 split_offset(int* i, const Strides4& m, std::size_t& o) const {
    const __m128i ql = _mm_cvttpd_epi32(lo), qh = _mm_cvttpd_epi32(hi);
    _mm_storel_epi64(reinterpret_cast<__m128i*>(i), ql);
    _mm_storel_epi64(reinterpret_cast<__m128i*>(i + 2), qh);
    // (i₀, i₁) and (i₂, i₃) into the low halves of 64-bit lanes, times the strides, summed: exact.
#if defined(__x86_64__) || defined(_M_X64)
    const __m128i z = _mm_setzero_si128();
    const __m128i p = _mm_add_epi64(_mm_mul_epu32(_mm_unpacklo_epi32(ql, z), m.m01), _mm_mul_epu32(_mm_unpacklo_epi32(qh, z), m.m23));
    o = static_cast<std::size_t>(_mm_cvtsi128_si64(_mm_add_epi64(p, _mm_unpackhi_epi64(p, p))));
#else
    o = m.dot(i);
#endif
    return {_mm_sub_pd(lo, _mm_cvtepi32_pd(ql)), _mm_sub_pd(hi, _mm_cvtepi32_pd(qh))};
  }
  HAIRLUT_SAMPLER_INLINE Vec4 abs() const {
    const __m128d m = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffffLL));
    return {_mm_and_pd(lo, m), _mm_and_pd(hi, m)};
  }
  HAIRLUT_SAMPLER_INLINE Vec4 sqrt() const { return {_mm_sqrt_pd(lo), _mm_sqrt_pd(hi)}; }
  static HAIRLUT_SAMPLER_INLINE Vec4 if_negative(const Vec4& x, const Vec4& a, const Vec4& b) {
    const __m128d ml = _mm_cmplt_pd(x.lo, _mm_setzero_pd()), mh = _mm_cmplt_pd(x.hi, _mm_setzero_pd());
    return {_mm_or_pd(_mm_and_pd(ml, a.lo), _mm_andnot_pd(ml, b.lo)), _mm_or_pd(_mm_and_pd(mh, a.hi), _mm_andnot_pd(mh, b.hi))};
  }
  friend HAIRLUT_SAMPLER_INLINE Vec4 operator*(const Vec4& a, const Vec4& b) { return {_mm_mul_pd(a.lo, b.lo), _mm_mul_pd(a.hi, b.hi)}; }
  HAIRLUT_SAMPLER_INLINE Vec4 nonnegative() const { return {_mm_max_pd(_mm_setzero_pd(), lo), _mm_max_pd(_mm_setzero_pd(), hi)}; }
  HAIRLUT_SAMPLER_INLINE double lane0() const { return _mm_cvtsd_f64(lo); }
  HAIRLUT_SAMPLER_INLINE double sum() const {
    const __m128d h = _mm_add_pd(lo, hi);  // (x₀ + x₂, x₁ + x₃)
    return _mm_cvtsd_f64(_mm_add_sd(h, _mm_unpackhi_pd(h, h)));
  }
  static HAIRLUT_SAMPLER_INLINE Vec4 sums(const Vec4& a, const Vec4& b, const Vec4& c) {
    // (x₀ + x₂, x₁ + x₃) per input, then the two halves.
    const __m128d sa = _mm_add_pd(a.lo, a.hi), sb = _mm_add_pd(b.lo, b.hi), sc = _mm_add_pd(c.lo, c.hi);
    const __m128d ab = _mm_add_pd(_mm_unpacklo_pd(sa, sb), _mm_unpackhi_pd(sa, sb));
    const __m128d cz = _mm_add_pd(_mm_unpacklo_pd(sc, _mm_setzero_pd()), _mm_unpackhi_pd(sc, _mm_setzero_pd()));
    return {ab, cz};
  }
  HAIRLUT_SAMPLER_INLINE void store(double* out) const { _mm_storeu_pd(out, lo), _mm_storeu_pd(out + 2, hi); }
  HAIRLUT_SAMPLER_INLINE void store3(double* out) const {
    _mm_storeu_pd(out, lo);
    out[2] = _mm_cvtsd_f64(hi);
  }
};
#endif

}  // namespace detail
}  // namespace sampler
}  // namespace hairlut
