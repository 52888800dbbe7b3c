// The sampling data stored next to the N_p and M_p tables (table_sampling.hpp, docs/table-format.md
// "Sampling data"): equal to what the sampler computes and to independent quadrature, clamp
// bounds that hold, and chi-square fits and furnaces of the renderer runtime reading them.
#include "sampling_checks.hpp"

using namespace sampling_checks;  // and the hairlut names it brings (sampling_checks.hpp)

namespace {

std::vector<sampler::Axis> views_of(const Table& t) {
  std::vector<sampler::Axis> v;
  for (const GridAxis& g : t.axes) v.push_back(g.view());
  return v;
}

// Every sampled table of the set has stored data, equal to the sampler's own computation, and
// its prefix integrals agree with composite Gauss–Legendre quadrature of the table's own
// interpolant (TableView, unclamped) along the sampled axis at node slices drawn at random.
void check_stored_against_quadrature(const TableSet& set, unsigned seed) {
  int sampled = 0;
  for (const SamplingDataCheck& c : check_sampling_data(set)) {
    INFO(c.table << ": " << c.problem);
    CHECK(c.present);
    CHECK(c.problem.empty());
    CHECK(c.max_cdf_difference == 0.0);
    CHECK(c.max_mass_difference == 0.0);
    CHECK(c.bound_mismatches == 0u);
    ++sampled;
  }
  CHECK(sampled > 0);
  std::mt19937_64 rng(seed);
  for (const Table& t : set.tables) {
    const auto measure = sampled_measure(t);
    if (!measure) continue;
    const sampler::AxisData d = stored_sampling_data(set, t);
    REQUIRE(d.cdf);
    const std::vector<sampler::Axis> axes = views_of(t);
    const int dims = static_cast<int>(axes.size());
    const sampler::TableView<float> view(t.f32.data(), axes.data(), dims);
    const sampler::Axis& last = axes.back();
    const int n = last.count;
    const std::size_t slices = t.f32.size() / static_cast<std::size_t>(n);
    const bool cosine = *measure == sampler::Measure::cosine, even = last.wrap == sampler::Wrap::even;
    for (int trial = 0; trial < 12; ++trial) {
      const std::size_t s = std::uniform_int_distribution<std::size_t>(0, slices - 1)(rng);
      std::vector<double> x(static_cast<std::size_t>(dims));
      std::size_t rest = s;
      for (int k = dims - 2; k >= 0; --k) {
        const std::size_t count = static_cast<std::size_t>(axes[static_cast<std::size_t>(k)].count);
        x[static_cast<std::size_t>(k)] = sampler::node(axes[static_cast<std::size_t>(k)], static_cast<int>(rest % count));
        rest /= count;
      }
      auto f = [&](double v) {
        x.back() = v;
        return view(x.data()) * (cosine ? std::cos(v) : 1.0);
      };
      double acc = 0.0, scale = 0.0;
      for (int k = 0; k < n; ++k) scale = std::max(scale, std::fabs(d.cdf[s * static_cast<std::size_t>(n) + static_cast<std::size_t>(k)]));
      for (int k = 0; k + 1 < n; ++k) {
        acc += integrate(f, sampler::node(last, k), sampler::node(last, k + 1), 1, 12);
        const double stored = d.cdf[s * static_cast<std::size_t>(n) + static_cast<std::size_t>(k + 1)];
        INFO(t.path() << " slice " << s << " node " << k + 1 << ": stored " << stored << ", quadrature " << acc);
        CHECK(std::fabs(stored - acc) <= 1e-11 * std::max(scale, 1e-300));
      }
      CHECK(std::fabs(d.mass[s] - acc * (even ? 2.0 : 1.0)) <= 1e-11 * std::max(scale, 1e-300));
    }
  }
}

// The clamp bounds hold: at random points of random cells of the other axes, the negative part of
// the unclamped interpolant integrated over each sampled cell (64-point Gauss–Legendre) does not
// exceed that cell's stored bound; where the bound is 0 the interpolant is ≥ 0 (to rounding).
void check_clamp_bounds(const TableSet& set, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const Table& t : set.tables) {
    if (!sampled_measure(t)) continue;
    const sampler::AxisData d = stored_sampling_data(set, t);
    REQUIRE(d.clamp_bound);
    const std::vector<sampler::Axis> axes = views_of(t);
    const int dims = static_cast<int>(axes.size());
    const sampler::TableView<float> view(t.f32.data(), axes.data(), dims);
    const sampler::Axis& last = axes.back();
    const std::size_t n = static_cast<std::size_t>(last.count);
    double peak = 0.0;
    for (float v : t.f32) peak = std::max(peak, static_cast<double>(std::fabs(v)));
    int clamped_cells = 0;
    for (int trial = 0; trial < 60; ++trial) {
      std::vector<double> x(static_cast<std::size_t>(dims));
      std::size_t first = 0, stride = 1;
      for (int k = dims - 2; k >= 0; --k) {
        const sampler::Axis& a = axes[static_cast<std::size_t>(k)];
        const int cells = sampler::axis_cells(a);
        const int c = std::uniform_int_distribution<int>(0, cells - 1)(rng);
        x[static_cast<std::size_t>(k)] = a.count <= 1 ? a.lo : sampler::node(a, c) + u(rng) * (sampler::node(a, std::min(c + 1, a.count - 1)) - sampler::node(a, c));
        first += static_cast<std::size_t>(c) * stride;
        stride *= static_cast<std::size_t>(a.count);
      }
      for (std::size_t k = 0; k + 1 < n; ++k) {
        const double bound = d.clamp_bound[first * n + k];
        const double negative = integrate(
            [&](double v) {
              x.back() = v;
              return std::max(0.0, -view(x.data()));
            },
            sampler::node(last, static_cast<int>(k)), sampler::node(last, static_cast<int>(k) + 1), 1, 64);
        if (negative > 0.0) ++clamped_cells;
        INFO(t.path() << " cell " << first << ", " << k << ": negative part " << negative << ", bound " << bound);
        // + the rounding of the interpolation itself (a few ulps of the largest node value).
        CHECK(negative <= bound * (1.0 + 1e-6) + 1e-13 * peak * (last.hi - last.lo) / static_cast<double>(n - 1));
      }
    }
    INFO(t.path() << ": " << clamped_cells << " sampled cells where the interpolant went below 0");
    SUCCEED();
  }
}

// Chi-square fit, ∫ pdf = 1 and the furnace against quadrature of eval, for the mixture of all
// lobes and for each explicit lobe alone, through the runtime reading the stored data (generic
// tables: the N_p tables' data along φ; the runtime lays M_p out along θi and computes those).
void stored_sampler_fits(const TableSet& set, const std::string& group, const sampler::Fiber& f, double theta_o, int fits, unsigned seed) {
  if (group.empty())
    for (const std::string& lobe : lobe_names(set)) REQUIRE(stored_sampling_data(set, *set.find("np/" + lobe)).cdf);
  const int lobes = static_cast<int>(lobe_names(set).size());
  for (int p = -1; p < lobes; ++p) {
    const OneGroup g = group_runtime(set, group, p, true);
    REQUIRE(g.runtime().valid());
    double integral = 0.0;
    const double pvalue = chi_square(g.runtime(), f, theta_o, 40000, seed + static_cast<unsigned>(p + 1), &integral);
    const Quadrature exact = quadrature_energy(set, group, g.runtime(), f, theta_o);
    const Estimate e = furnace(g.runtime(), f, theta_o, 100000, seed + 100 + static_cast<unsigned>(p + 1));
    INFO(group << " lobe " << g.lobe << " theta_o " << theta_o / kDeg << " deg: p-value " << pvalue << ", integral of pdf " << integral
               << ", furnace " << e.mean << " +- " << e.error << ", quadrature " << exact.value << " +- " << exact.error);
    CHECK(std::fabs(integral - 1.0) <= 1e-3);
    CHECK(pvalue > 0.01 / fits);
    CHECK(std::fabs(e.mean - exact.value) <= 4.0 * e.error + exact.error + kCutBias * exact.value);
  }
}

// Runs the sampler's blocks in reverse order (sampler::SerialBlocks' form).
struct ReverseBlocks {
  template <class Body>
  void operator()(std::size_t n, Body&& body) const {
    for (std::size_t i = n; i-- > 0;) body(i);
  }
};

}  // namespace

TEST_CASE("Sampling data: the default tables' stored data equal the sampler's and independent quadrature", "[sampling]") {
  check_stored_against_quadrature(default_tables(), 31);
}
TEST_CASE("Sampling data: the per-material tables' stored data equal the sampler's and independent quadrature", "[sampling]") {
  check_stored_against_quadrature(material_tables(), 32);
}
TEST_CASE("Sampling data: clamp bounds hold, default and per-material tables", "[sampling]") {
  check_clamp_bounds(default_tables(), 33);
  check_clamp_bounds(material_tables(), 34);
}
TEST_CASE("Sampling data: the sampler reads stored data or computes them, with the same result", "[sampling]") {
  // Every lobe of the default tables and their mixture, with and without the stored data: the same
  // draws and densities, bit for bit. With the stored data equal to the sampler's own (above),
  // this is why the chi-square fits and furnaces of the generic tables run once, on the computed
  // path (test_sampling.cpp): here they would repeat the same numbers.
  const TableSet& set = default_tables();
  const int lobes = static_cast<int>(lobe_names(set).size());
  std::mt19937_64 rng(35);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int p = -1; p < lobes; ++p) {
    const OneGroup stored = group_runtime(set, "", p, true), computed = group_runtime(set, "", p, false);
    REQUIRE(stored.runtime().valid());
    INFO("lobe " << stored.lobe);
    for (int k = 0; k < 200; ++k) {
      const sampler::Fiber f = grey_fiber((4.5 + 40.0 * u(rng)) * kDeg, 3.0 * u(rng));
      const Held wo((u(rng) - 0.5) * 170.0 * kDeg);
      const double v[3] = {u(rng), u(rng), u(rng)};
      const sampler::ScatteringSample r1 = stored.runtime().sample(f, wo.wo, v), r2 = computed.runtime().sample(f, wo.wo, v);
      CHECK(r1.theta_i == r2.theta_i);
      CHECK(r1.phi == r2.phi);
      CHECK(r1.pdf == r2.pdf);
      const double wi[3] = {std::sin(r1.theta_i), std::cos(r1.theta_i) * std::cos(r1.phi), std::cos(r1.theta_i) * std::sin(r1.phi)};
      CHECK(stored.runtime().pdf(f, wo.wo, wi) == computed.runtime().pdf(f, wo.wo, wi));
    }
  }
}
TEST_CASE("Sampling data: the clamp bounds' blocks give the same data in any order and on any thread count", "[sampling]") {
  // Every N_p and M_p table of the default set: the sampler's data computed with its blocks in
  // order (SerialBlocks), in reverse order, and by sampling_tables on one and on two threads.
  const TableSet& set = default_tables();
  int compared = 0;
  for (const Table& t : set.tables) {
    const auto m = sampled_measure(t);
    if (!m) continue;
    INFO(t.path());
    const std::vector<sampler::Axis> axes = views_of(t);
    const int dims = static_cast<int>(axes.size());
    const sampler::AxisSampler<float> in_order(t.f32.data(), axes.data(), dims, *m, sampler::AxisData(), sampler::SerialBlocks());
    const sampler::AxisSampler<float> reversed(t.f32.data(), axes.data(), dims, *m, sampler::AxisData(), ReverseBlocks());
    const sampler::AxisData a = in_order.sampling_data(), b = reversed.sampling_data();
    REQUIRE(a.cdf);
    REQUIRE(b.cdf);
    const std::size_t n = t.f32.size(), slices = in_order.slices();
    CHECK(std::equal(a.cdf, a.cdf + n, b.cdf));
    CHECK(std::equal(a.mass, a.mass + slices, b.mass));
    CHECK(std::equal(a.clamp_bound, a.clamp_bound + n, b.clamp_bound));
    ++compared;
  }
  CHECK(compared > 0);
  const std::vector<Table> one = sampling_tables(set, 1), two = sampling_tables(set, 2);
  REQUIRE(one.size() == two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    INFO(one[i].path());
    CHECK(one[i].f64 == two[i].f64);
    CHECK(one[i].f32 == two[i].f32);
  }
}
TEST_CASE("Sampling data: stored data, chi-square and furnace of every lobe, per-material tables", "[sampling]") {
  for (const char* material : {"blonde", "white"})
    for (const Case& c : kMaterialCases)
      stored_sampler_fits(material_tables(), std::string("materials/") + material, sampler::Fiber{}, c.theta_o, 20, 960);
}
TEST_CASE("Sampling data: an altered stored value is reported", "[sampling]") {
  TableSet set = material_tables();
  Table* cdf = nullptr;
  Table* bound = nullptr;
  for (Table& t : set.tables) {
    if (t.quantity == "sampling_cdf" && !cdf) cdf = &t;
    if (t.quantity == "sampling_clamp_bound" && !bound) bound = &t;
  }
  REQUIRE(cdf);
  REQUIRE(bound);
  cdf->f64[cdf->f64.size() / 2 + 1] *= 1.0 + 1e-9;
  bound->f32[0] = bound->f32[0] + 1.0f;
  // The last slice starts no cell (every other axis at its last node): its bounds are 0, and a
  // stored value there, finite or NaN, is a mismatch too.
  const std::size_t n = static_cast<std::size_t>(bound->axes.back().count), total = bound->f32.size();
  bound->f32[total - 2] = 0.5f;
  bound->f32[total - n] = std::nanf("");
  std::size_t mismatched = 0;
  double worst = 0.0;
  for (const SamplingDataCheck& c : check_sampling_data(set)) {
    mismatched += c.bound_mismatches;
    worst = std::max(worst, c.max_cdf_difference);
  }
  CHECK(mismatched == 3u);
  CHECK(worst > 1e-12);
}
