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
  for (int d = 0; d < 3; ++d) {
    double x[3] = {0.1, 0.5, 1.0};
    float xf[3] = {0.1f, 0.5f, 1.0f};
    x[d] = std::nan("");
    xf[d] = std::nanf("");
    CHECK(std::isnan(view(x)));
    CHECK(std::isnan(view_float(xf)));
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
