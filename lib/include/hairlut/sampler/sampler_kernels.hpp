// hairlut sampler, the kernels of the fixed-dimension views (sampler_fixed.hpp): the tensor product
// of each axis's taps for any mix of linear and cubic axes, the same with a cubic last axis four
// lanes at a time, and the multilinear blend of a cell as nested lerps (in SSE2 registers where
// the types allow). Header-only and dependency-free (C++17, with sampler_simd.hpp); FixedView
// picks one of these when it is built.
#pragma once

#include <cstddef>
#include <type_traits>
#include <utility>

#include "hairlut/sampler/sampler_simd.hpp"

namespace hairlut {
namespace sampler {

/// The taps of one axis at one coordinate, as offsets into the data (node index × stride).
/// Left uninitialized by default (a lookup fills the taps it uses: 2 for linear and geometric
/// axes, 4 for cubic ones).
template <class R>
struct FixedTaps {
  std::size_t off[4];
  R w[4];
};

namespace detail {

// Σ over the taps of axes d … D − 1 (N taps on axis d, then the rest), last axis innermost.
template <class T, class R, int N, int... Rest>
inline R fixed_product(const T* p, const FixedTaps<R>* tp) {
  if constexpr (sizeof...(Rest) == 0) {
    R s = tp->w[0] * static_cast<R>(p[tp->off[0]]);
    for (int k = 1; k < N; ++k) s += tp->w[k] * static_cast<R>(p[tp->off[k]]);
    return s;
  } else {
    R s = tp->w[0] * fixed_product<T, R, Rest...>(p + tp->off[0], tp + 1);
    for (int k = 1; k < N; ++k) s += tp->w[k] * fixed_product<T, R, Rest...>(p + tp->off[k], tp + 1);
    return s;
  }
}

// The multilinear interpolation of the cell at p (corner p, step[d] to the second node of axis
// d), each step a lerp (1 − w) a + w b (its two products independent: one multiply's latency per
// axis on the path from the loads to the result, where a + w (b − a) has a subtraction and a
// multiply), in one fixed order: the 2^D values as pairs along the last
// axis, the pairs combined over axes D − 3 … 0 (nested: T_A(q) = lerp_A(T_A+1(q), T_A+1(q + step
// A))), then over axis D − 2, then the last pair. lerp_cell_scalar does it one value at a time;
// lerp_cell below does the same operations on whole pairs in one register where it can (SSE2),
// with the same result.
template <class R>
struct LerpPair {
  R a, b;
};
template <class T, class R, int D, int A>
HAIRLUT_SAMPLER_INLINE LerpPair<R> pair_tree(const T* q, const std::ptrdiff_t* step, const R* w) {
  if constexpr (A == D - 2) {
    return {static_cast<R>(q[0]), static_cast<R>(q[step[D - 1]])};
  } else {
    const LerpPair<R> u = pair_tree<T, R, D, A + 1>(q, step, w), v = pair_tree<T, R, D, A + 1>(q + step[A], step, w);
    const R g = R(1) - w[A];
    return {g * u.a + w[A] * v.a, g * u.b + w[A] * v.b};
  }
}
template <class T, class R, int D>
HAIRLUT_SAMPLER_INLINE R lerp_cell_scalar(const T* p, const std::ptrdiff_t* step, const R* w) {
  if constexpr (D == 1) {
    const R a = static_cast<R>(p[0]), b = static_cast<R>(p[step[0]]);
    return (R(1) - w[0]) * a + w[0] * b;
  } else {
    const LerpPair<R> u = pair_tree<T, R, D, 0>(p, step, w), v = pair_tree<T, R, D, 0>(p + step[D - 2], step, w);
    const R g = R(1) - w[D - 2];
    const R a = g * u.a + w[D - 2] * v.a, b = g * u.b + w[D - 2] * v.b;
    return (R(1) - w[D - 1]) * a + w[D - 1] * b;
  }
}

#if HAIRLUT_SAMPLER_SSE2
// pair_tree with the pair in one register, in double: the pair at q (its step 1).
HAIRLUT_SAMPLER_INLINE __m128d load_pair(const float* q) {
  return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(q))));
}
HAIRLUT_SAMPLER_INLINE __m128d load_pair(const double* q) { return _mm_loadu_pd(q); }
// wb[A]: axis A's weight w in both halves.
template <class T, int D, int A>
HAIRLUT_SAMPLER_INLINE __m128d pair_tree_pd(const T* q, const std::ptrdiff_t* step, const __m128d* wb) {
  if constexpr (A == D - 2) {
    return load_pair(q);
  } else {
    const __m128d u = pair_tree_pd<T, D, A + 1>(q, step, wb), v = pair_tree_pd<T, D, A + 1>(q + step[A], step, wb);
    return _mm_add_pd(_mm_mul_pd(_mm_sub_pd(_mm_set1_pd(1.0), wb[A]), u), _mm_mul_pd(wb[A], v));
  }
}
// lerp_cell_scalar's value for a last axis of step 1 (T float or double), the weights of axes
// 0 … D − 2 broadcast in wb[] and the last one w_last.
template <class T, int D>
HAIRLUT_SAMPLER_INLINE double lerp_cell_pd(const T* p, const std::ptrdiff_t* step, const __m128d* wb, double w_last) {
  const __m128d u = pair_tree_pd<T, D, 0>(p, step, wb), v = pair_tree_pd<T, D, 0>(p + step[D - 2], step, wb);
  const __m128d r = _mm_add_pd(_mm_mul_pd(_mm_sub_pd(_mm_set1_pd(1.0), wb[D - 2]), u), _mm_mul_pd(wb[D - 2], v));
  const double a = _mm_cvtsd_f64(r), b = _mm_cvtsd_f64(_mm_unpackhi_pd(r, r));
  return (1.0 - w_last) * a + w_last * b;
}
// In float, two pairs per register: T_A(q) and T_A(q + step D − 2), so that the lerp over axis
// D − 2 is between the register's halves.
template <int D, int A>
HAIRLUT_SAMPLER_INLINE __m128 pair_tree_ps(const float* q, const std::ptrdiff_t* step, const float* w) {
  if constexpr (A == D - 2) {
    const __m128 lo = _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(q)));
    return _mm_loadh_pi(lo, reinterpret_cast<const __m64*>(q + step[D - 2]));
  } else {
    const __m128 u = pair_tree_ps<D, A + 1>(q, step, w), v = pair_tree_ps<D, A + 1>(q + step[A], step, w);
    return _mm_add_ps(_mm_mul_ps(_mm_set1_ps(1.0f - w[A]), u), _mm_mul_ps(_mm_set1_ps(w[A]), v));
  }
}
#endif

// lerp_cell_scalar's value, by pairs in one register where the types allow and the last axis's
// step is 1 (its second node next to the first, the usual case).
template <class T, class R, int D>
HAIRLUT_SAMPLER_INLINE R lerp_cell(const T* p, const std::ptrdiff_t* step, const R* w) {
#if HAIRLUT_SAMPLER_SSE2
  if constexpr (D >= 2 && std::is_same_v<R, double> && (std::is_same_v<T, float> || std::is_same_v<T, double>)) {
    if (step[D - 1] == 1) {
      __m128d wb[D - 1];
      for (int d = 0; d + 1 < D; ++d) wb[d] = _mm_set1_pd(w[d]);
      return lerp_cell_pd<T, D>(p, step, wb, w[D - 1]);
    }
  } else if constexpr (D >= 2 && std::is_same_v<R, float> && std::is_same_v<T, float>) {
    if (step[D - 1] == 1) {
      const __m128 u = pair_tree_ps<D, 0>(p, step, w);
      const __m128 r = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(1.0f - w[D - 2]), u), _mm_mul_ps(_mm_set1_ps(w[D - 2]), _mm_movehl_ps(u, u)));
      const float a = _mm_cvtss_f32(r), b = _mm_cvtss_f32(_mm_shuffle_ps(r, r, 1));
      return (1.0f - w[D - 1]) * a + w[D - 1] * b;
    }
  }
#endif
  return lerp_cell_scalar<T, R, D>(p, step, w);
}

// The product for a cubic mask (bit D − 1 − d set: axis d has 4 taps).
template <class T, class R, int D, int Mask, std::size_t... I>
inline R fixed_product_mask(const T* p, const FixedTaps<R>* tp, std::index_sequence<I...>) {
  return fixed_product<T, R, ((Mask >> (D - 1 - static_cast<int>(I))) & 1 ? 4 : 2)...>(p, tp);
}

template <class T, class R, int D>
using FixedKernel = R (*)(const T*, const FixedTaps<R>*);

// The product for a cubic last axis, four lanes at a time (Vec4: SSE2 registers): lane k holds
// the tensor product over axes 0 … D − 2 of the values at the last axis's tap k, nested as
// fixed_product nests them (each axis's taps summed pairwise: (t₀ + t₁) + (t₂ + t₃)), and the last
// axis's four weights are applied at the end, as one product of registers and a sum over lanes.
// The same terms as fixed_product, summed in another order: equal up to rounding. Contig: the four
// taps of the last axis are consecutive values (one load); otherwise they are gathered (next to an
// end, where they repeat or mirror).
template <class T, class R, bool Contig, int N, int... Rest>
HAIRLUT_SAMPLER_INLINE Vec4<R> vec_product(const T* p, const FixedTaps<R>* tp, const Vec4<R>* wv) {
  if constexpr (sizeof...(Rest) == 0) {
    static_assert(N == 4, "the last axis is cubic");
    if constexpr (Contig) return Vec4<R>::load_from(p + tp->off[0]);
    else return Vec4<R>::gather(p, tp->off);
  } else {
    const Vec4<R> a = wv[0] * vec_product<T, R, Contig, Rest...>(p + tp->off[0], tp + 1, wv + 4);
    const Vec4<R> b = wv[1] * vec_product<T, R, Contig, Rest...>(p + tp->off[1], tp + 1, wv + 4);
    if constexpr (N == 2) {
      return a + b;
    } else {
      const Vec4<R> c = wv[2] * vec_product<T, R, Contig, Rest...>(p + tp->off[2], tp + 1, wv + 4);
      const Vec4<R> d = wv[3] * vec_product<T, R, Contig, Rest...>(p + tp->off[3], tp + 1, wv + 4);
      return (a + b) + (c + d);
    }
  }
}
template <class T, class R, int D, int Mask, bool Contig, std::size_t... I>
HAIRLUT_SAMPLER_INLINE Vec4<R> vec_product_mask(const T* p, const FixedTaps<R>* tp, const Vec4<R>* wv, std::index_sequence<I...>) {
  return vec_product<T, R, Contig, ((Mask >> (D - 1 - static_cast<int>(I))) & 1 ? 4 : 2)...>(p, tp, wv);
}
/// The tensor product of the taps for a table whose last axis is cubic (Mask bit 0), by lanes.
template <class T, class R, int D, int Mask>
R fixed_product_cubic_last(const T* p, const FixedTaps<R>* tp) {
  static_assert(Mask & 1, "the last axis is cubic");
  using V = Vec4<R>;
  // The weights of axes 0 … D − 2 broadcast once (4 per axis; a linear axis uses 2).
  V wv[4 * (D - 1) + 1];
  for (int d = 0; d + 1 < D; ++d)
    for (int k = 0; k < ((Mask >> (D - 1 - d)) & 1 ? 4 : 2); ++k) wv[4 * d + k] = V::all(tp[d].w[k]);
  const FixedTaps<R>& last = tp[D - 1];
  const std::size_t o = last.off[0];
  const V lanes = last.off[1] == o + 1 && last.off[2] == o + 2 && last.off[3] == o + 3
                      ? vec_product_mask<T, R, D, Mask, true>(p, tp, wv, std::make_index_sequence<D>{})
                      : vec_product_mask<T, R, D, Mask, false>(p, tp, wv, std::make_index_sequence<D>{});
  return (lanes * V::load(last.w)).sum();
}

template <class T, class R, int D, int Mask>
R fixed_kernel(const T* p, const FixedTaps<R>* tp) {
  if constexpr ((Mask & 1) != 0) return fixed_product_cubic_last<T, R, D, Mask>(p, tp);
  else return fixed_product_mask<T, R, D, Mask>(p, tp, std::make_index_sequence<D>{});
}

template <class T, class R, int D, std::size_t... M>
FixedKernel<T, R, D> pick_kernel(int mask, std::index_sequence<M...>) {
  static constexpr FixedKernel<T, R, D> table[] = {&fixed_kernel<T, R, D, static_cast<int>(M)>...};
  return table[mask];
}

}  // namespace detail

}  // namespace sampler
}  // namespace hairlut
