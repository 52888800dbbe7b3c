// bench-hair-luts, section "representations": table size against the error a renderer sees and
// the cost of a lookup, per table representation, for the generic N_p domain and at the budgets
// of the engine presets.
//
// Error: at random points drawn uniformly over every axis's declared range (log-uniform on log
// axes), the table read exactly as a renderer reads it (TableSet::sample_value: each axis's
// interpolation, the energy factor of a normalized table) against direct evaluation (the Fourier
// method at 1e-12, independent of the table's nodes), relative to the peak over φ of the true
// slice at the same (β, σa, θd), floored at 1e-3 of the white fiber's (σa = 0) peak at the same
// (β, θd) (docs/conventions.md, "Error as a renderer sees it"). M_p: relative to the peak over θr
// at the same (β, θi).
// Cost: ns per lookup through sampler::FixedView (sampler_fixed.hpp: axis mappings prepared once,
// the tensor product compiled for the table's dimension), one thread, on random points, tables in
// cache where they fit; thread CPU time.
#include "representations.hpp"

#include "bench_common.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <hairlut/util/angles.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/physics/longitudinal_mp.hpp>
#include <hairlut/util/error.hpp>
#include <hairlut/sampler/sampler_fixed.hpp>
#include <hairlut/report/svg_plot.hpp>
#include <map>
#include <random>
#include <sstream>

namespace bench {
namespace {

using namespace hairlut;

using json = nlohmann::ordered_json;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

}  // namespace

ErrorStats error_stats(std::vector<double> e, std::vector<std::vector<double>> at) {
  ErrorStats s;
  if (e.empty()) return s;
  const auto imax = static_cast<std::size_t>(std::max_element(e.begin(), e.end()) - e.begin());
  s.worst = e[imax];
  s.where = at[imax];
  std::sort(e.begin(), e.end());
  s.p99 = e[static_cast<std::size_t>(0.99 * static_cast<double>(e.size() - 1))];
  return s;
}

double draw(const GridAxis& a, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  if (a.count == 1) return a.lo;
  if (a.spacing == Spacing::log) return std::exp(std::log(a.lo) + u(rng) * std::log(a.hi / a.lo));
  return a.lo + u(rng) * (a.hi - a.lo);
}

NpPoints np_points(const std::vector<GridAxis>& ax, const std::vector<std::string>& lobes, double eta, int slabs, std::uint64_t seed) {
  const int L = static_cast<int>(lobes.size());
  NpPoints pts;
  pts.lobes = lobes;
  pts.x.resize(static_cast<std::size_t>(L));
  pts.exact.resize(static_cast<std::size_t>(L));
  pts.den.resize(static_cast<std::size_t>(L));
  std::mt19937_64 rng(seed);
  constexpr int kBetas = 4, kPhis = 16, kDense = 721;
  const auto rules = std::make_shared<GaussLegendreCache>();
  for (int s = 0; s < slabs; ++s) {
    const double sigma = draw(ax[1], rng), theta = draw(ax[2], rng);
    std::vector<double> betas, phis;
    for (int b = 0; b < kBetas; ++b) betas.push_back(draw(ax[0], rng));
    for (int j = 0; j < kDense; ++j) phis.push_back(ax[3].lo + (ax[3].hi - ax[3].lo) * j / (kDense - 1));
    for (int j = 0; j < kPhis; ++j) phis.push_back(draw(ax[3], rng));
    NpGridRequest r;
    r.eta = eta;
    r.quadrature.method = NpQuadratureConfig::Method::fourier;
    r.quadrature.tolerance = 1e-12;
    r.lobes = L;
    r.sigmas = {sigma, 0.0};
    r.thetas = {theta};
    r.phis = phis;
    r.betas_of = [&](int) { return betas; };
    r.rules = rules;
    const std::size_t np = phis.size();
    std::vector<double> exact(static_cast<std::size_t>(L) * 2 * kBetas * np);
    auto at_ = [&](int p, int k, int b, std::size_t j) -> double& {
      return exact[((static_cast<std::size_t>(p) * 2 + static_cast<std::size_t>(k)) * kBetas + static_cast<std::size_t>(b)) * np + j];
    };
    BakeOptions o;
    bake_np_grid(r, o, "", [&](int p, std::size_t k, std::size_t, std::size_t b, std::size_t j, double v) {
      at_(p, static_cast<int>(k), static_cast<int>(b), j) = v;
    });
    for (int p = 0; p < L; ++p) {
      const auto P = static_cast<std::size_t>(p);
      for (int b = 0; b < kBetas; ++b) {
        double peak = 0.0, white = 0.0;
        for (std::size_t j = 0; j < kDense; ++j) peak = std::max(peak, at_(p, 0, b, j)), white = std::max(white, at_(p, 1, b, j));
        const double den = std::max(peak, 1e-3 * white);
        for (std::size_t j = kDense; j < np; ++j) {
          pts.x[P].push_back({betas[static_cast<std::size_t>(b)], sigma, theta, phis[j]});
          pts.exact[P].push_back(at_(p, 0, b, j));
          pts.den[P].push_back(den);
        }
      }
    }
  }
  return pts;
}

std::map<std::string, ErrorStats> np_errors(const NpPoints& pts, const std::function<double(int p, const std::vector<double>& x)>& value) {
  std::map<std::string, ErrorStats> out;
  for (std::size_t p = 0; p < pts.lobes.size(); ++p) {
    std::vector<double> err;
    err.reserve(pts.x[p].size());
    for (std::size_t i = 0; i < pts.x[p].size(); ++i)
      err.push_back(std::abs(value(static_cast<int>(p), pts.x[p][i]) - pts.exact[p][i]) / pts.den[p][i]);
    out[pts.lobes[p]] = error_stats(err, pts.x[p]);
  }
  return out;
}

namespace {

// The points of the generic N_p measure, computed once per domain (every representation of a
// domain is measured at the same points: they depend only on the axes' ranges and the seed).
const NpPoints& cached_np_points(const std::vector<GridAxis>& ax, const std::vector<std::string>& lobes, double eta, int slabs,
                                 std::uint64_t seed) {
  static std::map<std::string, NpPoints> cache;
  std::ostringstream key;
  key.precision(17);
  for (const GridAxis& a : ax) key << a.lo << " " << a.hi << " " << (a.spacing == Spacing::log) << " " << (a.count == 1) << ";";
  for (const std::string& l : lobes) key << l << ",";
  key << eta << ";" << slabs << ";" << seed;
  auto it = cache.find(key.str());
  if (it == cache.end()) it = cache.emplace(key.str(), np_points(ax, lobes, eta, slabs, seed)).first;
  return it->second;
}

// Sampled error of every generic N_p table of `set` (axes beta, sigma_a, theta_d, phi).
std::map<std::string, ErrorStats> np_errors(const TableSet& set, double eta, int slabs, std::uint64_t seed) {
  std::vector<std::string> lobes;
  for (const auto& l : set.metadata.at("lobes")) lobes.push_back(l.get<std::string>());
  std::vector<const Table*> tables;
  for (const std::string& l : lobes) tables.push_back(set.find("np/" + l));
  const NpPoints& pts = cached_np_points(tables.front()->axes, lobes, eta, slabs, seed);
  return np_errors(pts, [&](int p, const std::vector<double>& x) { return set.sample_value(*tables[static_cast<std::size_t>(p)], x); });
}

// Sampled error of an M_p table over (beta, theta_i, theta_r), relative to the peak over θr.
ErrorStats mp_errors(const Table& t, int points, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const double alpha = t.attributes.value("alpha", 0.0);
  std::vector<double> err;
  std::vector<std::vector<double>> at;
  constexpr int kPer = 8, kDense = 1441;
  for (int i = 0; i < points / kPer; ++i) {
    const double beta = draw(t.axes[0], rng), ti = draw(t.axes[1], rng);
    double peak = 0.0;
    for (int j = 0; j < kDense; ++j)
      peak = std::max(peak, longitudinal_deon_tilted(beta * beta, alpha, ti, -kHalfPi + 2.0 * kHalfPi * j / (kDense - 1)));
    for (int k = 0; k < kPer; ++k) {
      const double tr = draw(t.axes[2], rng);
      err.push_back(std::abs(t.sample({beta, ti, tr}) - longitudinal_deon_tilted(beta * beta, alpha, ti, tr)) / peak);
      at.push_back({beta, ti, tr});
    }
  }
  return error_stats(err, at);
}

// ns per lookup of the quantity a renderer reads (with the factor table, if any), through the
// fixed-dimension views of sampler_fixed.hpp (what the typed views use), D the table's axes.
template <int D>
double lookup_ns_fixed(const TableSet& set, const Table& t, int lookups, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<double> xs(static_cast<std::size_t>(lookups) * D);
  for (int i = 0; i < lookups; ++i)
    for (int d = 0; d < D; ++d) xs[static_cast<std::size_t>(i * D + d)] = draw(t.axes[static_cast<std::size_t>(d)], rng);
  std::vector<sampler::Axis> axes;
  for (const GridAxis& a : t.axes) axes.push_back(a.view());
  const sampler::FixedView<float, D> view(t.f32.data(), axes.data());
  const Table* f = t.factor().empty() ? nullptr : set.find(t.factor());
  std::vector<sampler::Axis> faxes;
  std::vector<int> fmap;
  if (f)
    for (const GridAxis& a : f->axes) {
      faxes.push_back(a.view());
      for (int d = 0; d < D; ++d)
        if (t.axes[static_cast<std::size_t>(d)].name == a.name) fmap.push_back(d);
    }
  if (f && (faxes.size() != 2 || fmap.size() != 2)) throw DomainError("table " + t.path() + ": the bench times factor tables of 2 axes");
  const sampler::FixedView<float, 2> fview(f ? f->f32.data() : nullptr, f ? faxes.data() : axes.data());
  double sink = 0.0;
  auto run = [&] {  // thread CPU time: wall time on a shared machine also counts the waits for a core
    const double t0 = thread_cpu_seconds();
    for (int i = 0; i < lookups; ++i) {
      const double* x = &xs[static_cast<std::size_t>(i * D)];
      double v = view(x);
      if (f) {
        const double y[2] = {x[fmap[0]], x[fmap[1]]};
        v *= fview(y);
      }
      sink += v;
    }
    return (thread_cpu_seconds() - t0) * 1e9 / lookups;
  };
  run();  // warm the caches
  double best = 1e300;
  for (int r = 0; r < 3; ++r) best = std::min(best, run());
  if (sink == -1.0) std::printf(" ");  // keep the loop
  return best;
}

double lookup_ns(const TableSet& set, const Table& t, int lookups, std::uint64_t seed) {
  if (t.axes.size() == 4) return lookup_ns_fixed<4>(set, t, lookups, seed);
  if (t.axes.size() == 3) return lookup_ns_fixed<3>(set, t, lookups, seed);
  throw DomainError("table " + t.path() + ": the bench times lookups in tables of 3 or 4 axes");
}

}  // namespace

// Per-lobe worst, p99 and worst point into a result row, and their largest over the lobes.
void add_errors(json& row, const std::map<std::string, ErrorStats>& errors) {
  double worst = 0.0, p99 = 0.0;
  for (const auto& [lobe, s] : errors) {
    row["worst"][lobe] = s.worst;
    row["p99"][lobe] = s.p99;
    row["worst_at"][lobe] = s.where;
    worst = std::max(worst, s.worst);
    p99 = std::max(p99, s.p99);
  }
  row["worst_all"] = worst;
  row["p99_all"] = p99;
}

namespace {

json axis(int count, const std::string& range_key, std::vector<double> range, const std::string& spacing, const std::string& interp) {
  json a = {{"count", count}, {range_key, range}, {"spacing", spacing}};
  if (!interp.empty()) a["interpolation"] = interp;
  return a;
}

// One generic N_p representation to measure.
struct NpCase {
  std::string representation, label;
  int beta, sigma, theta, phi;
};

json np_config(const NpCase& c, std::vector<double> beta_deg, double sigma_max, bool quick) {
  json np;
  json ax;
  if (c.representation == "multilinear") {
    ax["beta"] = axis(c.beta, "range_deg", beta_deg, "log", "");
    ax["sigma_a"] = axis(c.sigma, "range", {0, sigma_max}, "sqrt", "");
    ax["theta_d"] = axis(c.theta, "range_deg", {0, 89}, "cos", "");
    ax["phi"] = {{"count", c.phi}};
  } else if (c.representation == "uniform-multilinear") {
    ax["beta"] = axis(c.beta, "range_deg", beta_deg, "uniform", "");
    ax["sigma_a"] = axis(c.sigma, "range", {0, sigma_max}, "uniform", "");
    ax["theta_d"] = axis(c.theta, "range_deg", {0, 89}, "uniform", "");
    ax["phi"] = {{"count", c.phi}};
  } else if (c.representation == "geometric-sigma") {
    ax["beta"] = axis(c.beta, "range_deg", beta_deg, "log", "");
    ax["sigma_a"] = axis(c.sigma, "range", {0, sigma_max}, "uniform", "geometric");
    ax["theta_d"] = axis(c.theta, "range_deg", {0, 89}, "cos", "");
    ax["phi"] = {{"count", c.phi}};
  } else {  // shape-cubic, or shape-linear (the same axes read with linear interpolation, as a GPU filters a texture)
    const std::string order = c.representation == "shape-linear" ? "" : "cubic";
    ax["beta"] = axis(c.beta, "range_deg", beta_deg, "log", order);
    ax["sigma_a"] = axis(c.sigma, "range", {0, sigma_max}, "sqrt", c.sigma > 2 ? order : "");
    ax["theta_d"] = axis(c.theta, "range_deg", {0, 89}, "uniform", order);
    ax["phi"] = {{"count", c.phi}};
    if (!order.empty()) ax["phi"]["interpolation"] = order;
    np["normalize"] = "energy";
    // The energy factor on its own dense (σa, θd) axes: uniform σa read geometrically (exact for an
    // exponential fall in σa, which √σa spacing is not).
    np["energy_axes"] = {{"sigma_a", axis(c.sigma > 1 ? (quick ? 64 : 200) : 1, "range", {0, sigma_max}, "uniform", c.sigma > 1 ? "geometric" : "")},
                         {"theta_d", axis(quick ? 256 : 512, "range_deg", {0, 89}, "cos", order.empty() ? "" : "cubic")}};
  }
  if (c.sigma == 1) ax["sigma_a"] = {{"values", {0.0}}};
  np["axes"] = ax;
  return np;
}

}  // namespace

TableSet bake_tables(const json& tables, const std::string& name) {
  json doc = {{"name", name},
              {"model", "deon2011"},
              {"fiber", {{"eta", 1.55}}},
              {"lobes", {{"explicit", {"R", "TT", "TRT", "TRRT"}}, {"residual", false}, {"tilt_deg", {{"R", -4}, {"TT", 2}, {"TRT", 6}, {"TRRT", 10}}}}},
              {"tables", tables},
              {"output", {{"directory", "."}, {"basename", name}, {"formats", {"hdf5"}}}}};
  const BakeConfig c = parse_config(doc, name, ".");
  return bake(c);
}

json bench_representations(bool quick, bool quiet) {
  json rows = json::array();
  const int slabs = quick ? 40 : 300, lookups = quick ? 100000 : 1000000;
  auto say = [&](const std::string& s) {
    if (!quiet) std::fprintf(stderr, "representations: %s\n", s.c_str());
  };
  // The generic domain (β 2°–30°, σa 0–10, θd 0–89°, all φ; R, TT, TRT, TRRT).
  std::vector<NpCase> generic = {
      {"multilinear", "multilinear, sqrt sigma_a (what target_error 1e-3 chose before)", 19, 61, 126, 256},
      {"multilinear", "multilinear, sqrt sigma_a", 16, 32, 64, 128},
      {"geometric-sigma", "geometric sigma_a", 16, 32, 64, 128},
      {"shape-cubic", "shape N_p/E_p + cubic", 8, 8, 32, 64},
      {"shape-cubic", "shape N_p/E_p + cubic", 12, 12, 48, 96},
      {"shape-cubic", "shape N_p/E_p + cubic", 16, 16, 64, 128},
      {"shape-cubic", "shape N_p/E_p + cubic", 16, 24, 64, 128},
  };
  if (quick) generic = {generic[1], generic[2], generic[3]};
  // Engine budgets: N_p of a white fiber (unit attenuation) over (β, θd, φ) at HDRP's 64³.
  // The same budget (262 144 entries) split evenly, then allocated where the error is: few β
  // nodes (smooth in log β), many θd and φ nodes (the caustics move with θd and narrow with β).
  std::vector<NpCase> engine = {{"uniform-multilinear", "uniform multilinear 64^3", 64, 1, 64, 64},
                                {"shape-cubic", "hairlut shape + cubic 64^3", 64, 1, 64, 64},
                                {"shape-cubic", "hairlut shape + cubic, budget allocated", 12, 1, 128, 170},
                                {"shape-linear", "hairlut shape + multilinear, budget allocated", 12, 1, 128, 170}};
  std::vector<GridAxis> generic_axes;
  std::vector<std::string> generic_lobes;
  TableSet plain;  // the plain multilinear table of the generic domain: the Fourier lookups' reference
  auto run_np = [&](const NpCase& c, const std::string& domain, std::vector<double> beta_deg, double sigma_max) {
    say(domain + ": " + c.label + " " + std::to_string(c.beta) + "x" + std::to_string(c.sigma) + "x" + std::to_string(c.theta) + "x" +
        std::to_string(c.phi));
    TableSet set = bake_tables({{"np", np_config(c, beta_deg, sigma_max, quick)}}, "repr");
    const auto errors = np_errors(set, 1.55, slabs, 17);
    if (domain == "generic" && generic_axes.empty()) {
      generic_axes = set.find("np/R")->axes;
      for (const auto& l : set.metadata.at("lobes")) generic_lobes.push_back(l.get<std::string>());
    }
    std::size_t entries = 0, bytes = 0;
    for (const Table& t : set.tables) entries += t.size();
    bytes = set.bytes();
    json row = {{"domain", domain},
                {"representation", c.representation},
                {"label", c.label},
                {"counts", {{"beta", c.beta}, {"sigma_a", c.sigma}, {"theta_d", c.theta}, {"phi", c.phi}}},
                {"entries_per_lobe", set.find("np/R")->size()},
                {"entries_total", entries},
                {"bytes", bytes},
                {"points_per_lobe", slabs * 4 * 16}};
    add_errors(row, errors);
    row["lookup_ns"] = lookup_ns(set, *set.find("np/TRT"), lookups, 3);
    rows.push_back(row);
    if (domain == "generic" && c.representation == "multilinear" && c.beta == 16 && c.theta == 64) plain = std::move(set);
  };
  for (const NpCase& c : generic) run_np(c, "generic", {2, 30}, 10.0);
  // The detector's Fourier coefficients C_n(θd, σa) tabulated, β and φ exact, at the same points.
  for (const json& r : fourier_representation_rows(fourier_cases(quick), cached_np_points(generic_axes, generic_lobes, 1.55, slabs, 17),
                                                   generic_axes, 1.55, lookups, quiet, plain, quick))
    rows.push_back(r);
  for (const NpCase& c : engine) run_np(c, "engine-np-64^3", {2, 30}, 0.0);
  // Engine budgets: M_p over (β, θi, θr) at HDRP's 64³.
  // The same budget (64³ = 262 144 entries): evenly split, then allocated (12 β × 147 θi × 148 θr
  // = 261 072: M_p is smooth in log β, while its peak, as narrow as β, moves along θr with θi).
  struct MpCase {
    std::string representation, label;
    int beta, theta_i, theta_r;
  };
  for (const MpCase& c : std::vector<MpCase>{{"uniform-multilinear", "uniform-multilinear 64^3", 64, 64, 64},
                                             {"cubic", "cubic 64^3", 64, 64, 64},
                                             {"cubic", "cubic, budget allocated", 12, 147, 148},
                                             {"multilinear", "multilinear, budget allocated", 12, 147, 148}}) {
    const std::string& rep = c.representation;
    say("engine-mp-64^3: " + c.label);
    const bool cubic = rep == "cubic";
    json mp = {{"axes",
                {{"beta", axis(c.beta, "range_deg", {2, 30}, rep == "uniform-multilinear" ? "uniform" : "log", cubic ? "cubic" : "")},
                 {"theta_i", axis(c.theta_i, "range_deg", {-90, 90}, "uniform", cubic ? "cubic" : "")},
                 {"theta_r", axis(c.theta_r, "range_deg", {-90, 90}, "uniform", cubic ? "cubic" : "")}}}};
    const TableSet set = bake_tables({{"mp", mp}}, "repr-mp");
    json row = {{"domain", "engine-mp-64^3"},
                {"representation", rep},
                {"label", c.label},
                {"counts", {{"beta", c.beta}, {"theta_i", c.theta_i}, {"theta_r", c.theta_r}}},
                {"entries_per_lobe", c.beta * c.theta_i * c.theta_r},
                {"bytes", set.bytes()}};
    std::map<std::string, ErrorStats> errors;
    for (const std::string lobe : {"R", "TT", "TRT"}) errors[lobe] = mp_errors(*set.find("mp/" + lobe), quick ? 2000 : 20000, 5);
    add_errors(row, errors);
    row["lookup_ns"] = lookup_ns(set, *set.find("mp/R"), lookups, 4);
    rows.push_back(row);
  }
  return rows;
}

void write_representations(const json& rows, const json& machine, const std::string& out_dir) {
  json doc = {{"machine", machine},
              {"error_measure",
               "random points over every axis's declared range (log-uniform on log axes); table read as a renderer reads it "
               "(each axis's interpolation, the energy factor of a normalized table); reference: direct evaluation (Fourier "
               "method, 1e-12); N_p error relative to the peak over phi of the true slice at the same (beta, sigma_a, theta_d), "
               "floored at 1e-3 of the white fiber's peak at the same (beta, theta_d); M_p relative to the peak over theta_r at "
               "the same (beta, theta_i)"},
              {"rows", rows}};
  std::ofstream(out_dir + "/representations.json") << doc.dump(2) << "\n";
  std::ofstream csv(out_dir + "/representations.csv");
  csv << "domain,representation,label,entries_per_lobe,bytes,worst_R,worst_TT,worst_TRT,worst_TRRT,worst_all,p99_all,lookup_ns\n";
  std::ostringstream md;
  md << "| domain | representation | counts | entries per lobe | worst (R / TT / TRT / TRRT) | worst | p99 | lookup |\n"
        "|---|---|---|---|---|---|---|---|\n";
  auto g = [](const json& j, const char* k) { return j.contains(k) ? j.at(k).get<double>() : NAN; };
  auto f = [](double v) {
    if (std::isnan(v)) return std::string("-");
    char b[32];
    std::snprintf(b, sizeof b, "%.2g", v);
    return std::string(b);
  };
  auto counts_of = [](const json& r) {
    std::string counts;
    if (r.contains("counts"))
      for (const auto& [k, v] : r["counts"].items()) counts += (counts.empty() ? "" : " x ") + std::to_string(v.get<int>());
    return counts;
  };
  for (const json& r : rows) {
    const json w = r.value("worst", json::object());
    csv << r["domain"].get<std::string>() << "," << r["representation"].get<std::string>() << ",\"" << r["label"].get<std::string>() << "\","
        << r["entries_per_lobe"] << "," << r["bytes"] << "," << g(w, "R") << "," << g(w, "TT") << "," << g(w, "TRT") << "," << g(w, "TRRT")
        << "," << r["worst_all"] << "," << r["p99_all"] << "," << r["lookup_ns"] << "\n";
    const std::string counts = counts_of(r);
    md << "| " << r["domain"].get<std::string>() << " | " << r["label"].get<std::string>() << " | " << counts << " | "
       << r["entries_per_lobe"] << " | " << f(g(w, "R")) << " / " << f(g(w, "TT")) << " / " << f(g(w, "TRT")) << " / " << f(g(w, "TRRT"))
       << " | " << f(r["worst_all"].get<double>()) << " | " << f(r["p99_all"].get<double>()) << " | "
       << f(r["lookup_ns"].get<double>()) << " ns |\n";
  }
  bool fourier = false;
  for (const json& r : rows) {
    if (!r.contains("fourier")) continue;
    const json& f4 = r["fourier"];
    if (!fourier)
      md << "\nFourier rows (tables.np.representation fourier: C_n / F over theta_d x sigma_a baked by the library, read by "
            "sampler::FourierNp; beta and phi exact; terms for beta_min = 2 deg at the tolerance, rounded up to 4):\n\n";
    fourier = true;
    const json& tr = f4["truncation_alone"];
    md << "- " << r["label"].get<std::string>() << " " << counts_of(r) << ": stores " << f4["stored"].get<std::string>() << ", "
       << f4["theta_d_spacing"].get<std::string>() << " theta_d " << f4["theta_d_interpolation"].get<std::string>() << ", sqrt sigma_a "
       << f4["sigma_a_interpolation"].get<std::string>() << ", tolerance " << f(f4["tolerance"].get<double>()) << "; " << r["bytes"]
       << " bytes with the energy tables; truncation alone (exact C_n at the point, no table): worst " << f(tr["worst_all"].get<double>())
       << ", p99 " << f(tr["p99_all"].get<double>()) << "\n";
  }
  for (const json& r : rows) {
    if (!r.contains("fourier_lookup")) continue;
    const json& l = r["fourier_lookup"];
    md << "\nLookup of " << r["label"].get<std::string>() << " " << counts_of(r) << " (np_fourier/TRT, sampler::FourierNp) against a plain "
       << "multilinear lookup of " << l["multilinear_table"].get<std::string>() << " (sampler::FixedView) in the same run at the same points; "
       << l["timing"].get<std::string>() << "; load average " << l["load_average_before"].get<std::string>() << " before, "
       << l["load_average_after"].get<std::string>() << " after:\n\n"
       << "| points | cache | float: Fourier | float: multilinear | ratio | double: Fourier | double: multilinear | ratio |\n"
          "|---|---|---|---|---|---|---|---|\n";
    for (const json& x : l["rows"])
      md << "| " << x["points"].get<std::string>() << " | " << x["cache"].get<std::string>() << " | " << f(x["float"]["ns_fourier"].get<double>())
         << " ns | " << f(x["float"]["ns_multilinear"].get<double>()) << " ns | " << f(x["float"]["ratio"].get<double>()) << " | "
         << f(x["double"]["ns_fourier"].get<double>()) << " ns | " << f(x["double"]["ns_multilinear"].get<double>()) << " ns | "
         << f(x["double"]["ratio"].get<double>()) << " |\n";
  }
  std::ofstream(out_dir + "/representations.md") << md.str();
  // Pareto plot: entries per lobe against the worst sampled error, one series per representation.
  svg::LinePlot plot;
  plot.title = "Generic N_p: entries per lobe against worst sampled error";
  plot.xlabel = "entries per lobe";
  plot.ylabel = "worst error / local peak";
  plot.log_x = plot.log_y = true;
  std::map<std::string, svg::Series> series;
  for (const json& r : rows) {
    if (r["domain"] != "generic") continue;
    svg::Series& s = series[r["representation"].get<std::string>()];
    s.name = r["representation"].get<std::string>();
    s.markers = true;
    s.x.push_back(r["entries_per_lobe"].get<double>());
    s.y.push_back(r["worst_all"].get<double>());
  }
  for (auto& [k, s] : series) plot.series.push_back(s);
  plot.y_reference = 1e-3;
  std::ofstream(out_dir + "/representations.svg") << svg::line_plot(plot) << "\n";
}

}  // namespace bench
