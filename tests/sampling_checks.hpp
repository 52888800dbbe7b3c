// Shared by the sampling tests (test_sampling.cpp, test_sampling_mixture.cpp,
// test_sampling_stored.cpp): independent quadrature, the default and per-material tables, and
// chi-square and furnace estimators of the renderer runtime (HairScattering) at a held direction.
#pragma once

#include <algorithm>
#include <cmath>
#include <hairlut/physics/attenuation.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/physics/lobe_energy.hpp>
#include <hairlut/physics/longitudinal_mp.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/util/angles.hpp>
#include <hairlut/io/table_io.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/tables/table_sampling.hpp>
#include <hairlut/report/validate.hpp>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>
#include "catch.hpp"

namespace sampling_checks {
using namespace hairlut;
using sampler::AxisRow;
using sampler::AxisSampler;
using Runtime = sampler::HairScattering<float>;
}  // namespace sampling_checks

namespace sampling_checks {

constexpr double kDeg = kPi / 180.0;

// The axes of the random 3D test tables of the axis-sampling tests: a (log, 0.1–1) and b (uniform,
// 0–2) with their own interpolations, then the sampled axis — θr-like (clamped, −π/2 … π/2, for
// wrap 0) or φ-like (even, 0 … π) — with `interp`.
inline void random_table_axes(sampler::Axis axes[3], int na, int nb, int nx, int wrap, sampler::Interpolation a_interp,
                              sampler::Interpolation b_interp, sampler::Interpolation interp) {
  axes[0] = {sampler::Spacing::log, sampler::Placement::edges, sampler::Wrap::clamp, 0.1, 1.0, na, nullptr, a_interp};
  axes[1] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::clamp, 0.0, 2.0, nb, nullptr, b_interp};
  if (wrap == 0)
    axes[2] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::clamp, -0.5 * kPi, 0.5 * kPi, nx, nullptr, interp};
  else
    axes[2] = {sampler::Spacing::uniform, sampler::Placement::edges, sampler::Wrap::even, 0.0, kPi, nx, nullptr, interp};
}

// Gauss–Legendre nodes and weights of order m on [0, 1] (Newton on the Legendre recurrence).
inline void gauss_legendre01(int m, std::vector<double>& x, std::vector<double>& w) {
  x.assign(static_cast<std::size_t>(m), 0.0);
  w.assign(static_cast<std::size_t>(m), 0.0);
  for (int i = 0; i < m; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (m + 0.5)), dp = 0.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = 0.0;
      for (int j = 1; j <= m; ++j) {
        const double p2 = p1;
        p1 = p0;
        p0 = ((2.0 * j - 1.0) * z * p1 - (j - 1.0) * p2) / j;
      }
      dp = m * (z * p0 - p1) / (z * z - 1.0);
      const double dz = p0 / dp;
      z -= dz;
      if (std::fabs(dz) < 1e-16) break;
    }
    x[static_cast<std::size_t>(i)] = 0.5 * (1.0 - z);
    w[static_cast<std::size_t>(i)] = 1.0 / ((1.0 - z * z) * dp * dp);
  }
}

// ∫_a^b f by composite Gauss–Legendre of order m over `cells` equal cells.
template <class F>
double integrate(F f, double a, double b, int cells, int m = 8) {
  std::vector<double> x, w;
  gauss_legendre01(m, x, w);
  double s = 0.0;
  const double h = (b - a) / cells;
  for (int c = 0; c < cells; ++c)
    for (std::size_t g = 0; g < x.size(); ++g) s += w[g] * f(a + (c + x[g]) * h);
  return s * h;
}

// Upper tail of the chi-square distribution with k degrees of freedom (Wilson–Hilferty: the cube
// root of χ²/k is close to normal; accurate to a few percent of p for k ≥ 30).
inline double chi2_pvalue(double chi2, int k) {
  const double v = 2.0 / (9.0 * k);
  const double z = (std::cbrt(chi2 / k) - (1.0 - v)) / std::sqrt(v);
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

inline const TableSet& default_tables() {
  static const TableSet set = load_tables(std::string(HAIRLUT_SOURCE_DIR) + "/tables/default/hairlut-default.h5");
  return set;
}

// Per-material tables of two materials (one white) baked in memory, small enough for a test.
inline const TableSet& material_tables() {
  static const TableSet set = [] {
    const nlohmann::json j = nlohmann::json::parse(R"({
      "name": "sampling-test",
      "model": "deon2011",
      "fiber": { "eta": 1.55 },
      "lobes": { "explicit": ["R", "TT", "TRT", "TRRT"], "residual": true,
                 "tilt_deg": { "R": 0, "TT": 0, "TRT": 0, "TRRT": 0, "residual": 0 } },
      "tables": {
        "np": { "axes": { "theta_d": { "count": 40, "range_deg": [0, 89.5], "spacing": "cos" },
                          "phi": { "count": 97, "symmetry": "even" } } },
        "mp": { "axes": { "theta_i": { "count": 61, "range_deg": [-90, 90] },
                          "theta_r": { "count": 121, "range_deg": [-90, 90] } } }
      },
      "scene": { "mode": "per-material", "materials": [
        { "name": "blonde", "melanin": { "eumelanin": 0.3, "pheomelanin": 0.15 }, "beta_deg": { "R": 5, "TT": 2.5, "TRT": 10 } },
        { "name": "white", "sigma_a": [0.0, 0.0, 0.0], "beta_deg": { "R": 6, "TT": 6, "TRT": 6, "TRRT": 6, "residual": 6 } } ] },
      "output": { "basename": "sampling-test", "formats": ["hdf5"] }
    })");
    BakeOptions options;
    options.threads = 1;
    return bake(parse_config(j, "sampling-test.json", "."), options);
  }();
  return set;
}

// The renderer runtime over a group's tables ("" generic, or "materials/<name>"): all lobes (p < 0)
// or explicit lobe p alone (that one lobe, no residual: the runtime needs an explicit lobe, so the
// residual is checked in the mixture only). With `stored`,
// the N_p tables' sampling data stored in the file are read, else the runtime computes them.
struct OneGroup {
  std::unique_ptr<Runtime> rt;
  std::string lobe;  // "all" or the lobe's name
  const Runtime& runtime() const { return *rt; }
};
inline std::vector<std::string> lobe_names(const TableSet& set) {
  std::vector<std::string> names;
  for (const auto& l : set.metadata.at("lobes")) names.push_back(l.get<std::string>());
  return names;
}
inline OneGroup group_runtime(const TableSet& set, const std::string& group, int p, bool stored = true) {
  if (p < 0) {
    if (!group.empty() || stored) return {std::make_unique<Runtime>(hair_scattering<float>(set, group)), "all"};
    return {std::make_unique<Runtime>(hair_tables<float, double>(set)), "all"};
  }
  if (!group.empty()) {
    // One material's lobe p alone: a copy of the set that lists only that lobe and has no residual
    // (the material runtime copies its tables; the copy need not outlive it).
    TableSet one = set;
    const std::string lobe = lobe_names(set)[static_cast<std::size_t>(p)];
    one.metadata["lobes"] = nlohmann::ordered_json::array({lobe});
    std::erase_if(one.tables, [&](const Table& t) { return t.group == group && (t.name == "np_residual" || t.name == "mp_residual"); });
    return {std::make_unique<Runtime>(hair_scattering<float>(one, group)), lobe};
  }
  const sampler::HairTables<float, double> all = hair_tables<float, double>(set);
  REQUIRE(p < all.lobes);
  sampler::HairTables<float, double> one = all;
  one.lobes = 1, one.has_residual = false;
  one.np[0] = all.np[p], one.mp[0] = all.mp[p];
  for (int k = 1; k < all.beta_bands; ++k) one.np_band[k - 1][0] = all.np_band[k - 1][p];
  const std::string lobe = lobe_names(set)[static_cast<std::size_t>(p)];
  std::vector<sampler::AxisData> data(static_cast<std::size_t>(Runtime::kMaxBands * Runtime::kMaxLobes));
  data[0] = stored_sampling_data(set, *set.find("np/" + lobe));
  if (stored) REQUIRE(data[0].cdf);
  return {std::make_unique<Runtime>(one, stored ? data.data() : nullptr), lobe};
}

// A fiber of one σa in every channel and one β for M_p and N_p.
inline sampler::Fiber grey_fiber(double beta, double sigma_a) {
  sampler::Fiber f;
  f.beta_m = f.beta_n = beta;
  f.sigma_a[0] = f.sigma_a[1] = f.sigma_a[2] = sigma_a;
  return f;
}
// The held direction wo at inclination θo (φo = 0).
struct Held {
  double wo[3];
  explicit Held(double theta_o) : wo{std::sin(theta_o), std::cos(theta_o), 0.0} {}
};
inline double mean3(const double* rgb) { return (rgb[0] + rgb[1] + rgb[2]) / 3.0; }

// ∫ S cos θi dθi dφ (channels averaged) at held θo by quadrature of eval (independent of the
// sampling code): Gauss–Legendre between breakpoints where the interpolated S may have a kink —
// the nodes of the group's θi axes, θi = θo ∓ 2 θd at the nodes of its θd axes, and the nodes of
// its φ axes — so that each piece is smooth (a product of the tables' cell polynomials, times
// cos θi); φ over [0, π] (S is even in φ). On a piece the product is of degree 7 in θi (cubic M̃,
// linear Ê, N_p cubic along its θd axis) times cos θi and a smooth map where that axis is not
// linear in θd, and cubic in φ: 4 Gauss–Legendre nodes (exact to degree 7) leave only the error of
// those smooth factors. value: order 4 on every
// piece; error: |order 4 − order 3|, an upper estimate of the error of the order-4 value (on the
// default tables order 4 agrees with order 8 to 1e-11 of the value).
struct Quadrature {
  double value, error;
};
inline std::vector<double> pieces(std::vector<double> v, double lo, double hi) {
  v.push_back(lo), v.push_back(hi);
  std::erase_if(v, [&](double x) { return !(x >= lo && x <= hi); });
  std::sort(v.begin(), v.end());
  std::vector<double> out;
  for (double x : v)
    if (out.empty() || x - out.back() > 1e-9) out.push_back(x);
  return out;
}
inline Quadrature quadrature_energy(const TableSet& set, const std::string& group, const Runtime& rt, const sampler::Fiber& f, double theta_o) {
  std::vector<double> ti, ph;
  for (const Table& t : set.tables) {
    if (group.empty() ? t.group != "np" && t.group != "mp" : t.group != group) continue;
    for (const GridAxis& g : t.axes) {
      const sampler::Axis a = g.view();
      for (int k = 0; k < a.count; ++k) {
        const double x = sampler::node(a, k);
        if (g.name == "theta_i") ti.push_back(x);
        if (g.name == "theta_d") ti.push_back(theta_o - 2.0 * x), ti.push_back(theta_o + 2.0 * x);
        if (g.name == "phi") ph.push_back(x);
      }
    }
  }
  ti = pieces(ti, -0.5 * kPi, 0.5 * kPi), ph = pieces(ph, 0.0, kPi);
  auto at_order = [&](int m) {
    std::vector<double> x, w;
    gauss_legendre01(m, x, w);
    double total = 0.0;
    for (std::size_t i = 0; i + 1 < ti.size(); ++i)
      for (std::size_t a = 0; a < x.size(); ++a) {
        const double t = ti[i] + x[a] * (ti[i + 1] - ti[i]);
        double row = 0.0;
        for (std::size_t j = 0; j + 1 < ph.size(); ++j)
          for (std::size_t b = 0; b < x.size(); ++b) {
            double rgb[3];
            rt.eval(f, theta_o, t, ph[j] + x[b] * (ph[j + 1] - ph[j]), rgb);
            row += w[b] * (ph[j + 1] - ph[j]) * mean3(rgb);
          }
        total += w[a] * (ti[i + 1] - ti[i]) * 2.0 * std::cos(t) * row;
      }
    return total;
  };
  const double q4 = at_order(4), q3 = at_order(3);
  return {q4, std::fabs(q4 - q3)};
}

// The runtime never samples the θi cells where a lobe's M̃ stays below 1e-12 of its peak
// (product_row.hpp), so a furnace through sampling misses S there: at most 1e-12 of each lobe's
// peak over a few hundred cells of the half circle against a lobe at least 1° wide, below 1e-9 of
// ∫ S dω.
constexpr double kCutBias = 1e-9;

struct Estimate {
  double mean, error;  // mean and its standard error
};
// ∫ S dω at wo estimated from n samples' weights S / pdf (channels averaged).
inline Estimate furnace(const Runtime& rt, const sampler::Fiber& f, double theta_o, int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Runtime::ShadingPoint sp = rt.at(f, Held(theta_o).wo);
  double sum = 0.0, sum2 = 0.0;
  for (int k = 0; k < n; ++k) {
    const double v[3] = {u(rng), u(rng), u(rng)};
    const sampler::ScatteringSample r = sp.sample(v);
    const double x = r.pdf > 0.0 ? mean3(r.weight) : 0.0;
    sum += x;
    sum2 += x * x;
  }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n)};
}

// Chi-square test of n sampled directions against the pdf integrated over θi × φ bins.
// Returns the p-value; bins expecting fewer than 5 samples are pooled (Mitsuba's rule).
inline double chi_square(const Runtime& rt, const sampler::Fiber& f, double theta_o, int n, unsigned seed, double* pdf_integral) {
  const int nt = 60, np = 64;
  std::vector<double> observed(static_cast<std::size_t>(nt * np), 0.0), expected(observed.size(), 0.0);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Runtime::ShadingPoint sp = rt.at(f, Held(theta_o).wo);
  auto bin_of = [&](double ti, double phi) {
    const int i = std::min(nt - 1, std::max(0, static_cast<int>((ti + 0.5 * kPi) / kPi * nt)));
    const int j = std::min(np - 1, std::max(0, static_cast<int>((std::remainder(phi, 2.0 * kPi) + kPi) / (2.0 * kPi) * np)));
    return static_cast<std::size_t>(i * np + j);
  };
  for (int k = 0; k < n; ++k) {
    const double v[3] = {u(rng), u(rng), u(rng)};
    const sampler::ScatteringSample r = sp.sample(v);
    if (r.pdf > 0.0) observed[bin_of(r.theta_i, r.phi)] += 1.0;
  }
  std::vector<double> gx, gw;
  gauss_legendre01(6, gx, gw);
  double total = 0.0;
  const double ht = kPi / nt, hp = 2.0 * kPi / np;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j) {
      double e = 0.0;
      for (std::size_t a = 0; a < gx.size(); ++a)
        for (std::size_t b = 0; b < gx.size(); ++b) {
          const double ti = -0.5 * kPi + (i + gx[a]) * ht, phi = -kPi + (j + gx[b]) * hp;
          e += gw[a] * gw[b] * sp.pdf(ti, phi) * std::cos(ti);
        }
      e *= ht * hp;
      total += e;
      expected[static_cast<std::size_t>(i * np + j)] = e * n;
    }
  *pdf_integral = total;
  double chi2 = 0.0, pool_o = 0.0, pool_e = 0.0;
  int bins = 0;
  for (std::size_t k = 0; k < observed.size(); ++k) {
    if (expected[k] < 5.0) {
      pool_o += observed[k], pool_e += expected[k];
      continue;
    }
    chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
    ++bins;
  }
  if (pool_e > 0.0) chi2 += (pool_o - pool_e) * (pool_o - pool_e) / std::max(pool_e, 5.0), ++bins;
  return chi2_pvalue(chi2, bins - 1);
}

// The largest value of f over θi ∈ [−π/2, π/2] (4001 points).
template <class F>
double row_peak(F f) {
  double m = 0.0;
  for (int k = 0; k <= 4000; ++k) m = std::max(m, f(-0.5 * kPi + kPi * k / 4000.0));
  return m;
}

// Ê of one lobe at held θo (hair_scattering.hpp, step 1): the lobe's energy table interpolated
// linearly in (σa, θd) over its nodes, at θd = |θo − t_k|/2 on the M_p table's θi nodes t_k, then
// linearly in θi between those; from an independent lookup (TableView of the energy table with
// linear, clamped axes).
inline double energy_hat(const Table& energy, const GridAxis& theta_i_axis, double sigma_a, double theta_o, double theta_i) {
  sampler::Axis axes[2] = {energy.axes[0].view(), energy.axes[1].view()};
  for (sampler::Axis& a : axes) a.interpolation = sampler::Interpolation::linear, a.wrap = sampler::Wrap::clamp;
  // Ê interpolates the energies at the nodes: a table storing E / g (reaching 90°) times g at
  // each node.
  static std::map<const Table*, std::vector<float>> node_energies;
  const float* values = energy.f32.data();
  if (const sampler::GrazingFactor g = energy.grazing_factor(); !g.none()) {
    auto [it, fresh] = node_energies.try_emplace(&energy);
    if (fresh) {
      const auto sa = energy.axes[0].nodes(), td = energy.axes[1].nodes();
      it->second = energy.f32;
      for (std::size_t i = 0; i < it->second.size(); ++i)
        it->second[i] = static_cast<float>(it->second[i] * g(sa[i / td.size()], td[i % td.size()]));
    }
    values = it->second.data();
  }
  const sampler::TableView<float> view(values, axes, 2);
  const GridAxis& ti = theta_i_axis;
  const double h = (ti.hi - ti.lo) / (ti.count - 1), s = std::clamp((theta_i - ti.lo) / h, 0.0, ti.count - 1.0);
  const int k = std::min(static_cast<int>(s), ti.count - 2);
  auto at = [&](int j) {
    const double x[2] = {sigma_a, std::fabs(0.5 * (theta_o - (ti.lo + j * h)))};
    return view(x);
  };
  return at(k) + (s - k) * (at(k + 1) - at(k));
}

// The cases of the renderer tests: narrow and wide roughness, normal and grazing held directions.
struct Case {
  const char* name;
  double beta, theta_o;
};
const Case kGenericCases[] = {{"narrow", 4.5 * kDeg, 30.0 * kDeg}, {"wide", 30.0 * kDeg, -20.0 * kDeg}, {"grazing", 10.0 * kDeg, 85.0 * kDeg}};
const Case kMaterialCases[] = {{"normal", 0.0, 10.0 * kDeg}, {"grazing", 0.0, -85.0 * kDeg}};

}  // namespace sampling_checks
