// Grid axes and the header-only sampler: node placement, exact reproduction at nodes and of
// functions linear in the mapped coordinate, wrapping, folding and clamping.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <hairlut/tables/grid.hpp>
#include <hairlut/sampler/sampler.hpp>
#include <hairlut/util/angles.hpp>
#include <hairlut/util/error.hpp>
#include <vector>

#include "catch.hpp"

using namespace hairlut;

namespace {
GridAxis axis(Spacing s, Placement p, Wrap w, double lo, double hi, int n) {
  GridAxis a;
  a.name = "x";
  a.units = "1";
  a.spacing = s;
  a.placement = p;
  a.wrap = w;
  a.lo = lo;
  a.hi = hi;
  a.count = n;
  return a;
}
}  // namespace

TEST_CASE("Node placement follows the documented formulas", "[grid]") {
  // Edges: end nodes exactly at lo and hi; nodes evenly spaced in t(x).
  const GridAxis c = axis(Spacing::cos, Placement::edges, Wrap::clamp, 0.0, radians(89.0), 5);
  const auto n = c.nodes();
  CHECK(n.front() == 0.0);
  CHECK(n.back() == radians(89.0));
  for (int i = 0; i < 5; ++i)
    CHECK(std::cos(n[static_cast<std::size_t>(i)]) == Approx(1.0 + i / 4.0 * (std::cos(radians(89.0)) - 1.0)).epsilon(1e-14));
  // Centers: u = (i + 1/2)/n.
  const GridAxis l = axis(Spacing::log, Placement::centers, Wrap::clamp, 0.01, 100.0, 4);
  const auto m = l.nodes();
  for (int i = 0; i < 4; ++i) CHECK(std::log10(m[static_cast<std::size_t>(i)]) == Approx(-2.0 + (i + 0.5) / 4.0 * 4.0).epsilon(1e-14));
  // Periodic edges: count nodes at lo + i (hi − lo)/count (no duplicate of lo at hi).
  const GridAxis p = axis(Spacing::uniform, Placement::edges, Wrap::periodic, -kPi, kPi, 8);
  CHECK(p.nodes()[4] == Approx(0.0).margin(1e-15));
  CHECK(p.nodes()[7] == Approx(kPi - kPi / 4).epsilon(1e-15));
}

TEST_CASE("Sampling at nodes returns the stored value, and linear functions of t are exact", "[sampler]") {
  struct Case {
    Spacing s;
    Placement p;
    double lo, hi;
  };
  const Case cases[] = {{Spacing::uniform, Placement::edges, -1.0, 2.0}, {Spacing::cos, Placement::centers, 0.0, kHalfPi},
                        {Spacing::sin, Placement::edges, -kHalfPi, kHalfPi}, {Spacing::log, Placement::edges, 1e-3, 10.0},
                        {Spacing::sqrt, Placement::centers, 0.0, 16.0}};
  for (const Case& k : cases) {
    const GridAxis a = axis(k.s, k.p, Wrap::clamp, k.lo, k.hi, 7);
    const auto nodes = a.nodes();
    std::vector<double> data;
    for (double x : nodes) data.push_back(3.0 * sampler::mapped(k.s, x) + 1.0);  // linear in t
    const sampler::Axis v = a.view();
    for (std::size_t i = 0; i < nodes.size(); ++i) CHECK(sampler::sample(data.data(), &v, 1, &nodes[i]) == data[i]);
    // Between nodes a function linear in t is reproduced (inside the outermost nodes).
    for (double u = 0.05; u < 1.0; u += 0.1) {
      const double x = nodes.front() + u * (nodes.back() - nodes.front());
      CHECK(sampler::sample(data.data(), &v, 1, &x) == Approx(3.0 * sampler::mapped(k.s, x) + 1.0).epsilon(1e-12));
    }
    // Outside the outermost nodes the value is clamped.
    const double below = k.lo - 1.0, above = k.hi + 1.0;
    CHECK(sampler::sample(data.data(), &v, 1, &below) == data.front());
    CHECK(sampler::sample(data.data(), &v, 1, &above) == data.back());
  }
}

TEST_CASE("Lookups locate log axes with an ln within 4 ulps of a long double log, std::log off its domain", "[sampler]") {
  // The bound: the node index s = (ln x − ln lo) · scale then moves by at most 4 ulps of
  // max(1, |ln x|) · scale, the order of the affine step's own rounding. Reference: the x87 long
  // double log (64-bit mantissa), another algorithm.
  const auto check = [](double x) {
    const long double ref = std::log(static_cast<long double>(x));
    const double err = static_cast<double>(std::fabs(static_cast<long double>(sampler::ln_positive(x)) - ref));
    const double bound = 4.0 * 2.220446049250313e-16 * std::max(1.0, std::fabs(static_cast<double>(ref)));
    if (err > bound) FAIL_CHECK("ln_positive(" << x << ") off by " << err << " (bound " << bound << ")");
  };
  std::uint64_t state = 7;
  const auto next = [&state] {  // splitmix64
    std::uint64_t z = (state += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  for (int i = 0; i < 200000; ++i) {
    check(std::exp2(-1022.0 + 2045.0 * next()));  // every binade
    check(0.5 + 1.5 * next());                      // around 1, where ln x is small
    check(1e-3 + 20.0 * next());                    // the range of angles and σa
  }
  // The table's subinterval edges (bits(0.6875) + i · 2^44) and their neighbours, in two binades.
  for (std::uint64_t i = 0; i <= 256; ++i)
    for (double scale : {1.0, 0x1.0p-30}) {
      const std::uint64_t bits = 0x3fe6000000000000u + (i << 44);
      double z;
      std::memcpy(&z, &bits, sizeof z);
      for (double x : {std::nextafter(z, 0.0), z, std::nextafter(z, 2.0)}) check(x * scale);
    }
  CHECK(sampler::ln_positive(1.0) == Approx(0.0).margin(1e-16));
  CHECK(sampler::ln_positive(2.0) == std::log(2.0));
  // Off the positive normal numbers: std::log's values (−∞ at 0, NaN below, +∞, NaN), subnormals exact.
  for (double x : {0.0, -0.0, -1.0, std::numeric_limits<double>::denorm_min(), 1e-310, std::numeric_limits<double>::infinity(),
                   -std::numeric_limits<double>::infinity()}) {
    const double a = sampler::ln_positive(x), b = std::log(x);
    CHECK(((a == b) || (std::isnan(a) && std::isnan(b))));
  }
  CHECK(std::isnan(sampler::ln_positive(std::numeric_limits<double>::quiet_NaN())));
  CHECK(sampler::ln_positive(std::numeric_limits<double>::max()) == Approx(std::log(std::numeric_limits<double>::max())).epsilon(1e-15));
  CHECK(sampler::ln_positive(std::numeric_limits<double>::min()) == Approx(std::log(std::numeric_limits<double>::min())).epsilon(1e-15));
}

TEST_CASE("Periodic and even azimuth axes wrap", "[sampler]") {
  const GridAxis p = axis(Spacing::uniform, Placement::centers, Wrap::periodic, -kPi, kPi, 16);
  const auto nodes = p.nodes();
  std::vector<double> data;
  for (double x : nodes) data.push_back(std::cos(x));
  const sampler::Axis v = p.view();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double shifted = nodes[i] + 2 * kTwoPi;
    CHECK(sampler::sample(data.data(), &v, 1, &shifted) == Approx(data[i]).epsilon(1e-12));
  }
  // Halfway across the seam between the last and first node.
  const double seam = kPi;
  CHECK(sampler::sample(data.data(), &v, 1, &seam) == Approx(0.5 * (data.front() + data.back())).epsilon(1e-12));

  const GridAxis e = axis(Spacing::uniform, Placement::edges, Wrap::even, 0.0, kPi, 9);
  const sampler::Axis ev = e.view();
  std::vector<double> d2;
  for (double x : e.nodes()) d2.push_back(x * x);
  for (double x : {0.3, 1.0, 2.9}) {
    const double neg = -x, wrapped = x + kTwoPi, mirrored = kTwoPi - x;
    const double ref = sampler::sample(d2.data(), &ev, 1, &x);
    CHECK(sampler::sample(d2.data(), &ev, 1, &neg) == Approx(ref).epsilon(1e-14));
    CHECK(sampler::sample(d2.data(), &ev, 1, &wrapped) == Approx(ref).epsilon(1e-12));
    CHECK(sampler::sample(d2.data(), &ev, 1, &mirrored) == Approx(ref).epsilon(1e-12));
  }
}

TEST_CASE("Reflect axes fold by reflection about lo with period 2 (hi - lo)", "[sampler]") {
  // A function of cos 2x over [0, π/2]: even about 0 with period π, like η*(φh).
  const GridAxis a = axis(Spacing::uniform, Placement::edges, Wrap::reflect, 0.0, kHalfPi, 7);
  const sampler::Axis v = a.view();
  std::vector<double> d;
  for (double x : a.nodes()) d.push_back(std::cos(2.0 * x));
  for (double x : {0.1, 0.5, 1.2}) {
    const double ref = sampler::sample(d.data(), &v, 1, &x);
    for (double y : {-x, kPi - x, x + kPi, -x - 3.0 * kPi, x + 10.0 * kPi})
      CHECK(sampler::sample(d.data(), &v, 1, &y) == Approx(ref).epsilon(1e-12));
  }
  // At the nodes and their images: the stored values.
  const auto nodes = a.nodes();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double image = kPi - nodes[i];
    CHECK(sampler::sample(d.data(), &v, 1, &image) == Approx(d[i]).epsilon(1e-12));
  }
  CHECK(parse_wrap("reflect", "wrap") == Wrap::reflect);
  CHECK(to_string(Wrap::reflect) == "reflect");
}

TEST_CASE("Multilinear sampling in several dimensions", "[sampler]") {
  const GridAxis a = axis(Spacing::uniform, Placement::edges, Wrap::clamp, 0.0, 1.0, 3);
  const GridAxis b = axis(Spacing::log, Placement::centers, Wrap::clamp, 1.0, 100.0, 4);
  GridAxis c;
  c.name = "c";
  c.spacing = Spacing::explicit_values;
  c.values = {0.0, 0.1, 0.5, 2.0};
  c.count = 4;
  c.lo = 0.0;
  c.hi = 2.0;
  c.validate("c");
  const sampler::Axis axes[3] = {a.view(), b.view(), c.view()};
  // f = x + 2 log10(y) + 3 z is multilinear in (x, log y, z).
  std::vector<double> data;
  for (double x : a.nodes())
    for (double y : b.nodes())
      for (double z : c.nodes()) data.push_back(x + 2 * std::log10(y) + 3 * z);
  for (double x : {0.1, 0.5, 0.99})
    for (double y : {4.0, 20.0, 50.0})  // inside the outermost centre nodes 10^0.25 … 10^1.75
      for (double z : {0.05, 0.3, 1.9}) {
        const double pt[3] = {x, y, z};
        CHECK(sampler::sample(data.data(), axes, 3, pt) == Approx(x + 2 * std::log10(y) + 3 * z).epsilon(1e-12));
      }
}

TEST_CASE("Axis validation names the field", "[grid]") {
  auto message = [](const GridAxis& g) {
    try {
      g.validate("tables.np.axes.beta");
    } catch (const DomainError& e) {
      return std::string(e.what());
    }
    return std::string("(valid)");
  };
  CHECK(message(axis(Spacing::log, Placement::edges, Wrap::clamp, 0.0, 1.0, 4)).rfind("tables.np.axes.beta.range[0] must be > 0", 0) == 0);
  CHECK(message(axis(Spacing::uniform, Placement::edges, Wrap::clamp, 2.0, 1.0, 4)).rfind("tables.np.axes.beta.range must be increasing", 0) == 0);
  CHECK(message(axis(Spacing::cos, Placement::edges, Wrap::clamp, -0.1, 1.0, 4)).find("cos spacing") != std::string::npos);
  CHECK(message(axis(Spacing::uniform, Placement::edges, Wrap::clamp, 0.0, 1.0, 0)).rfind("tables.np.axes.beta.count must be >= 1", 0) == 0);
  CHECK(message(axis(Spacing::log, Placement::edges, Wrap::periodic, 1.0, 2.0, 4)).find("uniform spacing to be periodic") != std::string::npos);
  CHECK(message(axis(Spacing::uniform, Placement::edges, Wrap::clamp, 0.0, 1.0, 4)) == "(valid)");
}

// Catmull–Rom reproduces quadratics in the mapped coordinate, and the quadratic extrapolation
// beyond clamped ends keeps that true in the first and last cells.
TEST_CASE("Cubic interpolation is exact for quadratics of t, up to the clamped ends", "[sampler]") {
  for (Spacing s : {Spacing::uniform, Spacing::cos, Spacing::log, Spacing::sqrt}) {
    const double lo = s == Spacing::log ? 0.1 : 0.0, hi = s == Spacing::cos ? radians(89.0) : 4.0;
    GridAxis a = axis(s, Placement::edges, Wrap::clamp, lo, hi, 7);
    a.interpolation = Interpolation::cubic;
    auto f = [&](double x) {
      const double t = sampler::mapped(s, x);
      return 2.0 - 3.0 * t + 0.7 * t * t;
    };
    std::vector<double> v;
    for (double x : a.nodes()) v.push_back(f(x));
    const sampler::Axis view = a.view();
    for (int i = 0; i <= 200; ++i) {
      const double x = sampler::unmapped(s, sampler::mapped(s, lo) + i / 200.0 * (sampler::mapped(s, hi) - sampler::mapped(s, lo)));
      CHECK(sampler::sample(v.data(), &view, 1, &x) == Approx(f(x)).margin(1e-12));
    }
  }
}

TEST_CASE("Cubic interpolation across even and periodic azimuth ends uses the mirrored or wrapped node", "[sampler]") {
  // cos(2φ) on an even [0, π] axis and a periodic [−π, π) axis: the CR error of a smooth periodic
  // function is O(h^3); with 128 nodes per turn it stays below 1e-3 everywhere, including next to 0 and π,
  // which a clamped extrapolation would not give for an even function's zero slope.
  GridAxis even = axis(Spacing::uniform, Placement::edges, Wrap::even, 0.0, kPi, 65);
  GridAxis per = axis(Spacing::uniform, Placement::edges, Wrap::periodic, -kPi, kPi, 128);
  even.interpolation = per.interpolation = Interpolation::cubic;
  for (const GridAxis* a : {&even, &per}) {
    std::vector<double> v;
    for (double x : a->nodes()) v.push_back(std::cos(2.0 * x));
    const sampler::Axis view = a->view();
    double worst = 0.0;
    for (int i = -400; i <= 400; ++i) {
      const double x = i * kPi / 397.0;
      worst = std::max(worst, std::abs(sampler::sample(v.data(), &view, 1, &x) - std::cos(2.0 * x)));
    }
    CHECK(worst < 1e-3);
    // Symmetric: the value at -x equals the value at x.
    const double x1 = 0.0123, x2 = -0.0123;
    CHECK(sampler::sample(v.data(), &view, 1, &x1) == Approx(sampler::sample(v.data(), &view, 1, &x2)).margin(1e-14));
  }
}

TEST_CASE("Geometric interpolation is exact for exponentials and falls back to linear at zero", "[sampler]") {
  GridAxis a = axis(Spacing::uniform, Placement::edges, Wrap::clamp, 0.0, 10.0, 6);
  a.interpolation = Interpolation::geometric;
  std::vector<double> v;
  for (double x : a.nodes()) v.push_back(3.0 * std::exp(-1.7 * x));
  const sampler::Axis view = a.view();
  for (double x : {0.1, 1.3, 4.99, 7.7, 9.9}) CHECK(sampler::sample(v.data(), &view, 1, &x) == Approx(3.0 * std::exp(-1.7 * x)).epsilon(1e-12));
  v[5] = 0.0;  // linear in the last cell
  const double x = 9.0;
  CHECK(sampler::sample(v.data(), &view, 1, &x) == Approx(0.5 * v[4]).epsilon(1e-12));
  // Combined with a linear axis, the geometric axis is combined last: exact for f(x) g(y) with f
  // linear, g exponential.
  GridAxis b = axis(Spacing::uniform, Placement::edges, Wrap::clamp, 0.0, 1.0, 3);
  std::vector<sampler::Axis> axes = {a.view(), b.view()};
  std::vector<double> w;
  for (double xa : a.nodes())
    for (double xb : b.nodes()) w.push_back(std::exp(-1.7 * xa) * (1.0 + 2.0 * xb));
  const double p[2] = {3.3, 0.4};
  CHECK(sampler::sample(w.data(), axes.data(), 2, p) == Approx(std::exp(-1.7 * 3.3) * 1.8).epsilon(1e-12));
}

TEST_CASE("A NaN coordinate gives NaN, never a node's value, and a TableView equals sample()", "[sampler]") {
  GridAxis a = axis(Spacing::cos, Placement::edges, Wrap::clamp, 0.0, radians(89.0), 9);
  GridAxis b = axis(Spacing::uniform, Placement::edges, Wrap::even, 0.0, kPi, 17);
  b.interpolation = Interpolation::cubic;
  std::vector<float> v(9 * 17);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<float>(1.0 + 0.01 * static_cast<double>(i % 13));
  std::vector<sampler::Axis> axes = {a.view(), b.view()};
  const double nan_point[2] = {std::nan(""), 0.5};
  CHECK(std::isnan(sampler::sample(v.data(), axes.data(), 2, nan_point)));
  const sampler::TableView<float> view(v.data(), axes.data(), 2);
  for (int i = 0; i < 50; ++i) {
    const double x[2] = {0.03 * i, -3.0 + 0.13 * i};
    CHECK(view(x) == sampler::sample(v.data(), axes.data(), 2, x));
  }
}

TEST_CASE("Interpolation kinds are validated", "[grid]") {
  GridAxis e = channel_axis({"R", "G", "B"}, "channel");
  e.interpolation = Interpolation::cubic;
  CHECK_THROWS_AS(e.validate("x"), DomainError);
  GridAxis a = axis(Spacing::uniform, Placement::edges, Wrap::clamp, 0.0, 1.0, 4), b = a;
  a.interpolation = b.interpolation = Interpolation::geometric;
  CHECK_THROWS_AS(validate_interpolation({a, b}, "tables.np"), DomainError);
  // Round trip through JSON keeps the interpolation.
  a.name = "y";
  CHECK(GridAxis::from_json(a.to_json(), "y").interpolation == Interpolation::geometric);
}
