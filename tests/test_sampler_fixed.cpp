// Fixed-dimension sampler views (sampler_fixed.hpp) against the generic TableView: the same
// reconstruction for every wrap, spacing (explicit nodes included), placement and interpolation,
// in double and in float.
#include <cmath>
#include <hairlut/sampler/sampler_fixed.hpp>
#include <limits>
#include <random>
#include <vector>

#include "catch.hpp"

using namespace hairlut::sampler;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A random axis: every spacing, placement, wrap and interpolation, 1 to 9 nodes.
Axis random_axis(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Axis a;
  a.count = u(rng) < 0.1 ? 1 : 2 + static_cast<int>(u(rng) * 8);
  a.wrap = static_cast<Wrap>(static_cast<int>(u(rng) * 4));
  a.placement = u(rng) < 0.5 ? Placement::edges : Placement::centers;
  a.spacing = a.wrap == Wrap::periodic ? Spacing::uniform : static_cast<Spacing>(static_cast<int>(u(rng) * 5));
  a.interpolation = u(rng) < 0.5 ? Interpolation::linear : Interpolation::cubic;
  switch (a.spacing) {
    case Spacing::cos: a.lo = 0.1, a.hi = 1.4; break;
    case Spacing::sin: a.lo = -1.0, a.hi = 1.2; break;
    case Spacing::log: a.lo = 0.01, a.hi = 30.0; break;
    case Spacing::sqrt: a.lo = 0.0, a.hi = 16.0; break;
    default: a.lo = -1.0, a.hi = 2.0;
  }
  if (a.wrap == Wrap::even) a.spacing = Spacing::uniform, a.lo = 0.0, a.hi = kPi;
  if (a.spacing == Spacing::sqrt && a.wrap == Wrap::clamp && u(rng) < 0.5) a.lo_end = End::mirror;
  if (a.wrap == Wrap::clamp && a.count > 1 && u(rng) < 0.2) {
    // Explicit nodes (linear in x): strictly increasing, kept alive for the test's duration.
    static std::vector<std::vector<double>> pool;
    std::vector<double> v(static_cast<std::size_t>(a.count));
    double x = -1.0;
    for (double& n : v) n = x += 0.05 + u(rng);
    pool.push_back(v);
    a.spacing = Spacing::explicit_values, a.values = pool.back().data(), a.lo = v.front(), a.hi = v.back();
    a.interpolation = Interpolation::linear;
  }
  return a;
}

// A coordinate inside, outside, at a node, or (wrapping axes) several periods away.
double random_coordinate(const Axis& a, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  if (a.count > 1 && u(rng) < 0.15) return node(a, static_cast<int>(u(rng) * a.count));
  double x = a.lo - 0.5 + u(rng) * (a.hi - a.lo + 1.0);
  if (a.wrap != Wrap::clamp) x = -2.0 * kPi + 4.0 * kPi * u(rng);
  if (a.spacing == Spacing::log && x <= 0.0) x = 1e-3;
  return x;
}

template <int D>
void compare_random_tables(int tables, int points, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst = 0.0, worst_float = 0.0;
  for (int t = 0; t < tables; ++t) {
    Axis axes[D];
    for (Axis& a : axes) a = random_axis(rng);
    if (u(rng) < 0.4) axes[static_cast<int>(u(rng) * D)].interpolation = Interpolation::geometric;
    std::size_t n = 1;
    for (const Axis& a : axes) n *= static_cast<std::size_t>(a.count);
    std::vector<float> v(n);
    for (float& x : v) x = static_cast<float>(0.1 + u(rng));  // positive: geometric applies
    const TableView<float> generic(v.data(), axes, D);
    const FixedView<float, D> fixed(v.data(), axes);
    const FixedView<float, D, float> fixed_float(v.data(), axes);
    for (int k = 0; k < points; ++k) {
      double x[D];
      float xf[D];
      for (int d = 0; d < D; ++d) {
        xf[d] = static_cast<float>(random_coordinate(axes[d], rng));
        x[d] = xf[d];
      }
      const double ref = generic(x);
      // Double: the same sums in another order. Values in [0.1, 1.1] and Catmull–Rom weights
      // (Σ|w| ≤ 1.25 per axis) bound Σ|w v| by 1.1 · 1.25^D; 16 ulps of that.
      const double bound = 16.0 * 2.220446049250313e-16 * 1.1 * std::pow(1.25, D);
      worst = std::max(worst, std::abs(fixed(x) - ref) / bound);
      // Float: mapped and summed in float; ~1e-6 of the values' scale.
      worst_float = std::max(worst_float, std::abs(static_cast<double>(fixed_float(xf)) - ref));
    }
  }
  CHECK(worst <= 1.0);
  CHECK(worst_float <= 2e-5);
}

}  // namespace

TEST_CASE("Fixed views equal TableView for every axis kind, 1 to 4 axes, double and float", "[sampler]") {
  compare_random_tables<1>(400, 100, 11);
  compare_random_tables<2>(400, 100, 12);
  compare_random_tables<3>(400, 100, 13);
  compare_random_tables<4>(400, 100, 14);
}

TEST_CASE("Fixed views return stored values at nodes and NaN for a NaN coordinate", "[sampler]") {
  Axis axes[3];
  axes[0].spacing = Spacing::log, axes[0].lo = 0.03, axes[0].hi = 0.8, axes[0].count = 5, axes[0].interpolation = Interpolation::cubic;
  axes[1].spacing = Spacing::cos, axes[1].lo = 0.0, axes[1].hi = 1.5, axes[1].count = 7, axes[1].wrap = Wrap::clamp;
  axes[2].spacing = Spacing::uniform, axes[2].lo = 0.0, axes[2].hi = kPi, axes[2].count = 9, axes[2].wrap = Wrap::even,
  axes[2].interpolation = Interpolation::cubic;
  std::vector<float> v(5 * 7 * 9);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<float>(std::sin(0.37 * static_cast<double>(i)) + 2.0);
  const FixedView<float, 3> view(v.data(), axes);
  const FixedView<float, 3, float> view_float(v.data(), axes);
  for (int a = 0; a < 5; ++a)
    for (int b = 0; b < 7; ++b)
      for (int c = 0; c < 9; ++c) {
        const double x[3] = {node(axes[0], a), node(axes[1], b), node(axes[2], c)};
        const float xf[3] = {static_cast<float>(x[0]), static_cast<float>(x[1]), static_cast<float>(x[2])};
        const double stored = v[static_cast<std::size_t>((a * 7 + b) * 9 + c)];
        CHECK(view(x) == Approx(stored).epsilon(1e-14));
        CHECK(view_float(xf) == Approx(stored).epsilon(1e-5));
      }
  // The same axes all linear take the lanes path (every axis located in one register), whose
  // NaN test is on the mapped coordinates; and a sqrt axis, clamped, as the σa axis is.
  Axis linear[3] = {axes[0], axes[1], axes[2]};
  for (Axis& a : linear) a.interpolation = Interpolation::linear;
  linear[1].spacing = Spacing::sqrt, linear[1].lo = 0.0, linear[1].hi = 16.0;
  const FixedView<float, 3> lanes(v.data(), linear);
  const FixedView<float, 3, float> lanes_float(v.data(), linear);
  for (int d = 0; d < 3; ++d) {
    double x[3] = {0.1, 0.5, 1.0};
    float xf[3] = {0.1f, 0.5f, 1.0f};
    x[d] = std::nan("");
    xf[d] = std::nanf("");
    CHECK(std::isnan(view(x)));
    CHECK(std::isnan(view_float(xf)));
    CHECK(std::isnan(lanes(x)));
    CHECK(std::isnan(lanes_float(xf)));
  }
}

// The register path of the multilinear cell (pairs along the last axis in SSE2 registers) and the
// one-value-at-a-time path do the same IEEE operations in the same order: equal bit for bit.
template <class T, class R, int D>
void compare_cell_paths(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<T> v(4096);
  for (T& x : v) x = static_cast<T>(u(rng) * 4.0 - 1.0);
  int differ = 0;
  for (int k = 0; k < 2000; ++k) {
    std::ptrdiff_t step[D];
    R w[D];
    for (int d = 0; d < D; ++d) step[d] = 1 + static_cast<std::ptrdiff_t>(u(rng) * 200.0), w[d] = static_cast<R>(u(rng));
    step[D - 1] = 1;  // the register path's case
    const T* p = v.data() + static_cast<std::size_t>(u(rng) * 100.0);
    const R a = detail::lerp_cell<T, R, D>(p, step, w), b = detail::lerp_cell_scalar<T, R, D>(p, step, w);
    differ += a == b ? 0 : 1;
  }
  CHECK(differ == 0);
}

TEST_CASE("The register and scalar paths of the multilinear cell give the same bits", "[sampler]") {
  compare_cell_paths<float, double, 1>(1);
  compare_cell_paths<float, double, 2>(2);
  compare_cell_paths<float, double, 3>(3);
  compare_cell_paths<float, double, 4>(4);
  compare_cell_paths<double, double, 3>(5);
  compare_cell_paths<double, double, 4>(6);
  compare_cell_paths<float, float, 2>(7);
  compare_cell_paths<float, float, 3>(8);
  compare_cell_paths<float, float, 4>(9);
}

// The shapes renderers look up (N_p: β log, σa sqrt, θd and φ even; M_p: β log, θi, θr), with
// the default tables' node counts, at random points and at ±∞ (an infinite azimuth folds to NaN,
// which both views send to the last node).
TEST_CASE("Fixed views equal TableView on the default tables' shapes, and at infinite coordinates", "[sampler]") {
  Axis np[4], mp[3];
  np[0].spacing = Spacing::log, np[0].lo = 0.07, np[0].hi = 0.79, np[0].count = 12;
  np[1].spacing = Spacing::sqrt, np[1].lo = 0.0, np[1].hi = 16.0, np[1].count = 12;
  np[2].wrap = Wrap::even, np[2].lo = 0.0, np[2].hi = 1.55, np[2].count = 48;
  np[3].wrap = Wrap::even, np[3].lo = 0.0, np[3].hi = kPi, np[3].count = 96;
  mp[0] = np[0];
  mp[1].lo = -kPi / 2, mp[1].hi = kPi / 2, mp[1].count = 121;
  mp[2].lo = -kPi / 2, mp[2].hi = kPi / 2, mp[2].count = 161;
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<float> v4(12 * 12 * 48 * 96), v3(12 * 121 * 161);
  for (float& x : v4) x = static_cast<float>(0.1 + u(rng));
  for (float& x : v3) x = static_cast<float>(0.1 + u(rng));
  const TableView<float> g4(v4.data(), np, 4), g3(v3.data(), mp, 3);
  const FixedView<float, 4> f4(v4.data(), np);
  const FixedView<float, 3> f3(v3.data(), mp);
  const double inf = std::numeric_limits<double>::infinity();
  double worst = 0.0;
  for (int k = 0; k < 20000; ++k) {
    double x[4], y[3];
    for (int d = 0; d < 4; ++d) x[d] = random_coordinate(np[d], rng);
    for (int d = 0; d < 3; ++d) y[d] = random_coordinate(mp[d], rng);
    if (k % 10 == 0) x[k % 4] = (k / 10) % 2 ? inf : -inf, y[k % 3] = (k / 10) % 2 ? inf : -inf;
    worst = std::max(worst, std::abs(f4(x) - g4(x)) / (16.0 * 2.220446049250313e-16 * 1.1));
    worst = std::max(worst, std::abs(f3(y) - g3(y)) / (16.0 * 2.220446049250313e-16 * 1.1));
  }
  CHECK(worst <= 1.0);
}

// The cubic-last-axis kernel (four values of the last axis per register, its weights applied at
// the end) against the scalar tensor product over the same taps (detail::fixed_product, one value
// at a time) and against TableView: equal up to rounding, i.e. within a few ulps of Σ|w · v|, at
// random points that favour the end cells, where the taps repeat (clamped ends), mirror (even θd
// at 0, even φ at 0 and π, a mirrored √σa end) or wrap (periodic φ).
namespace {

// Axes of the kinds the tables use, cubic or linear; the last one always cubic.
Axis kernel_axis(std::mt19937_64& rng, bool last) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Axis a;
  a.count = 4 + static_cast<int>(u(rng) * 9);
  a.interpolation = last || u(rng) < 0.6 ? Interpolation::cubic : Interpolation::linear;
  switch (static_cast<int>(u(rng) * 6)) {
    case 0: a.lo = -1.0, a.hi = 2.0; break;                                              // clamped both ends
    case 1: a.spacing = Spacing::log, a.lo = 0.03, a.hi = 0.8; break;                   // β
    case 2: a.spacing = Spacing::sqrt, a.lo = 0.0, a.hi = 10.0, a.lo_end = End::mirror; break;  // √σa from 0
    case 3: a.wrap = Wrap::even, a.lo = 0.0, a.hi = 89.0 * kPi / 180.0; break;          // θd: mirror at 0
    case 4: a.wrap = Wrap::even, a.lo = 0.0, a.hi = kPi; break;                          // φ: mirror at 0 and π
    default: a.wrap = Wrap::periodic, a.lo = -kPi, a.hi = kPi; break;                    // periodic φ
  }
  if (u(rng) < 0.2) a.placement = Placement::centers;
  return a;
}

// A coordinate in the first or last cell, at a node, or anywhere (beyond the ends for clamped axes).
double kernel_coordinate(const Axis& a, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double r = u(rng);
  if (r < 0.1) return node(a, static_cast<int>(u(rng) * a.count));
  if (r < 0.35) return node(a, 0) + u(rng) * (node(a, 1) - node(a, 0));
  if (r < 0.6) return node(a, a.count - 2) + u(rng) * (node(a, a.count - 1) - node(a, a.count - 2));
  if (a.wrap == Wrap::periodic) return -3.0 * kPi + 6.0 * kPi * u(rng);
  if (a.spacing == Spacing::log) return a.lo * std::pow(a.hi / a.lo, -0.1 + 1.2 * u(rng));
  if (a.spacing == Spacing::sqrt) return a.hi * 1.1 * u(rng);
  return a.lo - 0.3 + (a.hi - a.lo + 0.6) * u(rng);
}

template <class R, int D, int Mask>
void compare_cubic_kernel(std::mt19937_64& rng, double& worst, double& worst_view, double& worst_gather) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Axis axes[D];
  for (int d = 0; d < D; ++d) {
    axes[d] = kernel_axis(rng, d == D - 1);
    axes[d].interpolation = (Mask >> (D - 1 - d)) & 1 ? Interpolation::cubic : Interpolation::linear;
  }
  std::size_t n = 1;
  for (const Axis& a : axes) n *= static_cast<std::size_t>(a.count);
  std::vector<float> v(n), av(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<float>(u(rng) * 2.0 - 0.5), av[i] = std::fabs(v[i]);
  const FixedView<float, D, R> view(v.data(), axes);
  const TableView<float> generic(v.data(), axes, D);
  const double eps = std::numeric_limits<R>::epsilon();
  for (int k = 0; k < 200; ++k) {
    R x[D];
    double xd[D];
    FixedTaps<R> tp[D], at[D];
    for (int d = 0; d < D; ++d) {
      x[d] = static_cast<R>(kernel_coordinate(axes[d], rng)), xd[d] = x[d];
      tp[d] = view.axis(d).taps(x[d]);
      at[d] = tp[d];
      for (int j = 0; j < ((Mask >> (D - 1 - d)) & 1 ? 4 : 2); ++j) at[d].w[j] = std::fabs(at[d].w[j]);
    }
    const auto seq = std::make_index_sequence<D>{};
    const R scalar = detail::fixed_product_mask<float, R, D, Mask>(v.data(), tp, seq);
    const R lanes = detail::fixed_kernel<float, R, D, Mask>(v.data(), tp);
    const double scale = static_cast<double>(detail::fixed_product_mask<float, R, D, Mask>(av.data(), at, seq));  // Σ|w · v|
    worst = std::max(worst, std::abs(static_cast<double>(lanes) - static_cast<double>(scalar)) / (8.0 * eps * scale + 1e-300));
    // The view (the same kernel) against TableView's own taps and sums; in float the coordinates
    // are mapped in float (sampler_fixed.hpp: ~1e-6 of the values' scale).
    const double tol = std::is_same_v<R, double> ? 16.0 * eps * scale : 2e-5;
    worst_view = std::max(worst_view, std::abs(static_cast<double>(view(x)) - generic(xd)) / (tol + 1e-300));
    // Gathering the last axis's four values gives the bits of loading them at once.
    const FixedTaps<R>& l = tp[D - 1];
    if (l.off[1] == l.off[0] + 1 && l.off[2] == l.off[0] + 2 && l.off[3] == l.off[0] + 3) {
      detail::Vec4<R> wv[4 * D];
      for (int d = 0; d + 1 < D; ++d)
        for (int j = 0; j < ((Mask >> (D - 1 - d)) & 1 ? 4 : 2); ++j) wv[4 * d + j] = detail::Vec4<R>::all(tp[d].w[j]);
      const R a = (detail::vec_product_mask<float, R, D, Mask, true>(v.data(), tp, wv, seq) * detail::Vec4<R>::load(l.w)).sum();
      const R b = (detail::vec_product_mask<float, R, D, Mask, false>(v.data(), tp, wv, seq) * detail::Vec4<R>::load(l.w)).sum();
      worst_gather = std::max(worst_gather, a == b ? 0.0 : 1.0);
    }
  }
}

template <class R, int D, int Mask = 1>
void compare_cubic_kernels(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  double worst = 0.0, worst_view = 0.0, worst_gather = 0.0;
  for (int t = 0; t < 60; ++t) compare_cubic_kernel<R, D, Mask>(rng, worst, worst_view, worst_gather);
  CHECK(worst <= 1.0);
  CHECK(worst_view <= 1.0);
  CHECK(worst_gather == 0.0);
  if constexpr (Mask + 2 < (1 << D)) compare_cubic_kernels<R, D, Mask + 2>(seed + 1);
}

}  // namespace

TEST_CASE("The cubic-last-axis kernel equals the scalar tensor product up to rounding, end cells included", "[sampler]") {
  compare_cubic_kernels<double, 1>(31);
  compare_cubic_kernels<double, 2>(32);
  compare_cubic_kernels<double, 3>(33);
  compare_cubic_kernels<double, 4>(34);
  compare_cubic_kernels<float, 1>(35);
  compare_cubic_kernels<float, 2>(36);
  compare_cubic_kernels<float, 3>(37);
  compare_cubic_kernels<float, 4>(38);
}

// The register lanes (detail::Vec4 with SSE2) and the array lanes do the same IEEE operations:
// the same bits, NaN and the clamp's second-operand rule included.
template <class R>
void compare_lanes(std::uint64_t seed) {
  using S = detail::Vec4<R, true>;
  using A = detail::Vec4<R, false>;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  auto bits = [](const auto& x) {
    R a[4];
    if constexpr (std::is_same_v<std::decay_t<decltype(x)>, A>) {
      for (int k = 0; k < 4; ++k) a[k] = x.v[k];
    } else {
      R t[3];
      x.store3(t);
      a[0] = t[0], a[1] = t[1], a[2] = t[2], a[3] = x.template lane<3>().lane0();
    }
    return std::vector<R>(a, a + 4);
  };
  int differ = 0;
  for (int k = 0; k < 2000; ++k) {
    float f[4];
    R r[4], q[4];
    for (int j = 0; j < 4; ++j) f[j] = static_cast<float>(u(rng)), r[j] = static_cast<R>(u(rng)), q[j] = static_cast<R>(u(rng));
    if (k % 7 == 0) r[k % 4] = std::numeric_limits<R>::quiet_NaN();
    const S s = S::load_from(f) * S::load(r) + S::load(q), ss = S::load(r) - S::load(q);
    const A a = A::load_from(f) * A::load(r) + A::load(q), aa = A::load(r) - A::load(q);
    const auto same = [](const std::vector<R>& x, const std::vector<R>& y) {
      for (int j = 0; j < 4; ++j)
        if (!(x[j] == y[j] || (x[j] != x[j] && y[j] != y[j]))) return false;
      return true;
    };
    differ += same(bits(s), bits(a)) ? 0 : 1;
    differ += same(bits(S::min(s, ss)), bits(A::min(a, aa))) ? 0 : 1;
    differ += same(bits(S::max(ss, s)), bits(A::max(aa, a))) ? 0 : 1;
    differ += same(bits(s.abs()), bits(a.abs())) ? 0 : 1;
    differ += same(bits(s.template lane<1>()), bits(a.template lane<1>())) ? 0 : 1;
    differ += S::greater(s, ss) == A::greater(a, aa) ? 0 : 1;
    const R ssum = s.sum(), asum = a.sum();
    differ += ssum == asum || (ssum != ssum && asum != asum) ? 0 : 1;
    differ += same(bits(S::sums(s, ss, s)), bits(A::sums(a, aa, a))) ? 0 : 1;
    R pos[4];
    for (int j = 0; j < 4; ++j) pos[j] = std::fabs(q[j]) * R(40);
    int is[4], ia[4];
    const S fs = S::load(pos).split(is);
    const A fa = A::load(pos).split(ia);
    differ += same(bits(fs), bits(fa)) && is[0] == ia[0] && is[1] == ia[1] && is[2] == ia[2] && is[3] == ia[3] ? 0 : 1;
    // The cell's offset Σ i_k · stride_k, multiplied in registers (32 × 32 → 64 bits) against
    // the scalar sum, strides up to 2³² − 1 (products beyond 2³²).
    const std::size_t strides[4] = {static_cast<std::size_t>(k) * 2147483u + 1u, 4294967295u, static_cast<std::size_t>(k % 97), 1u};
    const detail::Strides4 m(strides);
    std::size_t os = 0, oa = 0;
    const S gs = S::load(pos).split_offset(is, m, os);
    const A ga = A::load(pos).split_offset(ia, m, oa);
    std::size_t expect = 0;
    for (int j = 0; j < 4; ++j) expect += static_cast<std::size_t>(static_cast<int>(pos[j])) * strides[j];
    differ += same(bits(gs), bits(ga)) && os == expect && oa == expect ? 0 : 1;
    const std::size_t off[4] = {3, 0, 2, 2};
    differ += same(bits(S::gather(f, off)), bits(A::gather(f, off))) ? 0 : 1;
  }
  CHECK(differ == 0);
}

TEST_CASE("Register lanes and array lanes give the same bits", "[sampler]") {
#if HAIRLUT_SAMPLER_SSE2
  compare_lanes<float>(41);
  compare_lanes<double>(42);
#else
  SUCCEED("no SSE2 on this target: the array lanes are the only ones");
#endif
}
