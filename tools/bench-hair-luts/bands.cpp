// Section "bands": the lookup cost of N_p baked in β bands (beta_bands.hpp; the banded layout below,
// shipped as tables/configs/generic-1e-3.json until the Fourier representation replaced it there)
// against a plain multilinear 4D lookup in the same sampler. The banded lookup is
// what a renderer does per call: pick the band of β, the band table's cubic reconstruction on every
// axis (4^4 taps), times the energy factor's 2D lookup (sampler::HairTables::np_value). The plain
// lookup reads the same band-0 table with every axis linear (2^4 taps) and no factor. Both in float
// arithmetic (R = float) and double, at the same random points (β log-uniform over the config's
// range, σa, θd, φ uniform), in cache (256 points repeated) and out of cache (2^20 points).
// A cheaper reconstruction is timed next to it: the same band tables read linearly along β and
// σa and cubically along θd and φ (4² · 2² = 64 taps instead of 256), with the error it gives by
// the validator's measure (measure_sampled_error, the same random points and reference as
// validate-hair-luts) next to the error of the baked all-cubic reconstruction, on every band's
// TRT table: a faster reconstruction is never reported without its accuracy.
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/sampled_error.hpp>
#include <hairlut/bake/table_truth.hpp>
#include <hairlut/tables/beta_bands.hpp>
#include <hairlut/sampler/sampler_fiber.hpp>
#include <hairlut/sampler/sampler_fixed.hpp>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include "bench_common.hpp"

namespace bench {

namespace {

using namespace hairlut;

// N_p over the generic domain in four β bands (2–3°, 3–5°, 5–10°, 10–30°): the shape N_p / E_p,
// cubic on every axis, √σa mirrored at 0; 3.73 M N_p entries per lobe over the bands and energy
// tables of 200 √σa × 283 cos θd nodes (tables/configs/generic-1e-3.json before it took the
// Fourier representation).
nlohmann::json banded_config() {
  return nlohmann::json::parse(R"({
    "name": "generic-1e-3-bands",
    "model": "deon2011",
    "fiber": { "eta": 1.55 },
    "lobes": { "explicit": ["R", "TT", "TRT", "TRRT"], "residual": true },
    "quadrature": { "method": "fourier", "tolerance": 1e-12 },
    "tables": { "np": {
      "normalize": "energy",
      "axes": {
        "beta": {"count": 4, "range_deg": [2, 30], "spacing": "log", "interpolation": "cubic"},
        "sigma_a": {"count": 10, "range": [0, 10], "spacing": "sqrt", "interpolation": "cubic", "lo_end": "mirror"},
        "theta_d": {"count": 224, "range_deg": [0, 89], "spacing": "uniform", "interpolation": "cubic"},
        "phi": {"count": 232, "interpolation": "cubic"} },
      "beta_bands": [
        {"beta": {"count": 4, "range_deg": [2, 3], "spacing": "log", "interpolation": "cubic"}, "theta_d": {"count": 224}, "phi": {"count": 232}},
        {"beta": {"count": 4, "range_deg": [3, 5], "spacing": "log", "interpolation": "cubic"}, "theta_d": {"count": 140}, "phi": {"count": 154}},
        {"beta": {"count": 5, "range_deg": [5, 10], "spacing": "log", "interpolation": "cubic"}, "theta_d": {"count": 84}, "phi": {"count": 112}},
        {"beta": {"count": 9, "range_deg": [10, 30], "spacing": "log", "interpolation": "cubic"}, "theta_d": {"count": 56}, "phi": {"count": 64}} ],
      "energy_axes": {
        "sigma_a": {"count": 200, "range": [0, 10], "spacing": "sqrt", "interpolation": "cubic", "lo_end": "mirror"},
        "theta_d": {"count": 283, "range_deg": [0, 89], "spacing": "cos", "interpolation": "cubic"} } } },
    "output": { "directory": ".", "basename": "generic-1e-3-bands", "formats": ["hdf5"] }
  })");
}

struct Points {
  std::vector<float> beta, sigma, theta, phi;
};

Points draw(std::size_t n, double beta_lo, double beta_hi, double sigma_hi, double theta_hi, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Points p;
  for (std::size_t i = 0; i < n; ++i) {
    p.beta.push_back(static_cast<float>(std::exp(std::log(beta_lo) + u(rng) * (std::log(beta_hi) - std::log(beta_lo)))));
    p.sigma.push_back(static_cast<float>(u(rng) * sigma_hi));
    p.theta.push_back(static_cast<float>(u(rng) * theta_hi));
    p.phi.push_back(static_cast<float>(u(rng) * 3.14159265358979323846));
  }
  return p;
}

// The TRT views of every band, as hair_tables fills them (the set has no M_p tables); with
// linear_beta_sigma, β and σa read linearly (θd, φ and the energy factor as baked).
template <class R>
sampler::HairTables<float, R> trt_bands(const TableSet& set, bool linear_beta_sigma) {
  sampler::HairTables<float, R> h;
  const Table& t0 = *set.find("np/TRT");
  const Table& energy = *set.find(t0.factor());
  sampler::Axis ea[2] = {energy.axes[0].view(), energy.axes[1].view()};
  h.beta_bands = static_cast<int>(set.metadata.at("np_beta_bands").size());
  for (int k = 0; k < h.beta_bands; ++k) {
    const Table& b = *set.find("np/TRT" + beta_band_suffix(k));
    sampler::Axis ba[4];
    for (int d = 0; d < 4; ++d) ba[d] = b.axes[static_cast<std::size_t>(d)].view();
    if (linear_beta_sigma) ba[0].interpolation = ba[1].interpolation = sampler::Interpolation::linear;
    h.band_hi[k] = b.axes[0].hi;
    (k == 0 ? h.np[2] : h.np_band[k - 1][2]) = sampler::NpLobe<float, R>(b.f32.data(), ba, energy.f32.data(), ea, energy.grazing_factor());
  }
  return h;
}

template <class R>
json measure(const TableSet& set, const Points& pts, std::size_t calls, int repeats) {
  const sampler::HairTables<float, R> h = trt_bands<R>(set, false), hl = trt_bands<R>(set, true);
  const Table& t0 = *set.find("np/TRT");
  sampler::Axis lin[4];
  for (int d = 0; d < 4; ++d) {
    lin[d] = t0.axes[static_cast<std::size_t>(d)].view();
    lin[d].interpolation = sampler::Interpolation::linear;
    lin[d].lo_end = sampler::End::extrapolate;
  }
  const sampler::FixedView<float, 4, R> plain(t0.f32.data(), lin);
  const std::size_t n = pts.beta.size();
  volatile R sink = 0;
  const double banded = best_ns(calls, repeats, [&] {
    R s = 0;
    for (std::size_t i = 0, k = 0; i < calls; ++i, k = k + 1 == n ? 0 : k + 1)
      s += h.np_value(2, static_cast<R>(pts.beta[k]), static_cast<R>(pts.sigma[k]), static_cast<R>(pts.theta[k]), static_cast<R>(pts.phi[k]));
    sink = sink + s;
  });
  const double banded_lin = best_ns(calls, repeats, [&] {
    R s = 0;
    for (std::size_t i = 0, k = 0; i < calls; ++i, k = k + 1 == n ? 0 : k + 1)
      s += hl.np_value(2, static_cast<R>(pts.beta[k]), static_cast<R>(pts.sigma[k]), static_cast<R>(pts.theta[k]), static_cast<R>(pts.phi[k]));
    sink = sink + s;
  });
  const double linear = best_ns(calls, repeats, [&] {
    R s = 0;
    for (std::size_t i = 0, k = 0; i < calls; ++i, k = k + 1 == n ? 0 : k + 1) {
      const R x[4] = {static_cast<R>(pts.beta[k]), static_cast<R>(pts.sigma[k]), static_cast<R>(pts.theta[k]), static_cast<R>(pts.phi[k])};
      s += plain(x);
    }
    sink = sink + s;
  });
  return {{"ns_banded_cubic_factor", banded}, {"ns_banded_linear_beta_sigma_factor", banded_lin}, {"ns_plain_multilinear", linear},
          {"ratio", banded / linear}, {"ratio_linear_beta_sigma", banded_lin / linear}};
}

// The validator's sampled error (worst, 99th percentile) of every band's TRT table with the baked
// reconstruction (cubic on every axis) and with β and σa read linearly.
json band_errors(TableSet& set, std::size_t points, int threads) {
  const auto rule = std::make_shared<const GaussLegendreRule>(1024);
  TruthModel model;
  model.eta = set.metadata.at("eta").get<double>();
  model.path = parse_absorption_path(set.metadata.at("absorption_path").get<std::string>());
  model.explicit_lobes = static_cast<int>(set.metadata.at("lobes").size());
  json out = json::array();
  const int bands = static_cast<int>(set.metadata.at("np_beta_bands").size());
  for (int k = 0; k < bands; ++k) {
    Table& t = *const_cast<Table*>(set.find("np/TRT" + beta_band_suffix(k)));
    const auto truth = table_truth(t, model, rule);
    SampledErrorOptions so;
    so.points = points, so.threads = threads;
    so.seed = 1469598103934665603ULL;  // FNV-1a of the path, as the validator seeds each table
    for (unsigned char c : t.path()) so.seed = (so.seed ^ c) * 1099511628211ULL;
    const SampledError cubic = measure_sampled_error(set, t, *truth, so);
    const Interpolation b = t.axes[0].interpolation, sg = t.axes[1].interpolation;
    t.axes[0].interpolation = t.axes[1].interpolation = Interpolation::linear;
    const SampledError lin = measure_sampled_error(set, t, *truth, so);
    t.axes[0].interpolation = b, t.axes[1].interpolation = sg;
    out.push_back({{"table", t.path()}, {"beta_range_deg", {t.axes[0].lo * 180.0 / 3.14159265358979323846, t.axes[0].hi * 180.0 / 3.14159265358979323846}},
                   {"points", cubic.error.points}, {"cubic_worst", cubic.error.worst}, {"cubic_p99", cubic.error.p99},
                   {"linear_beta_sigma_worst", lin.error.worst}, {"linear_beta_sigma_p99", lin.error.p99}});
  }
  return out;
}

}  // namespace

json bench_bands(const Settings& s) {
  const std::string config = "the banded generic-domain layout of bands.cpp";
  log(s.quiet, "bands: baking %s in memory\n", config.c_str());
  const BakeConfig c = parse_config(banded_config(), "bands", s.out_dir.empty() ? "." : s.out_dir);
  BakeOptions opt;
  const auto t0 = clock_type::now();
  BakeReport report;
  TableSet set = bake(c, opt, &report);
  const double bake_s = seconds_since(t0);
  std::size_t entries = 0;
  json bands = json::array();
  for (const Table& t : set.tables)
    if (t.group == "np" && t.quantity == "N_p" && t.attributes.value("lobe", std::string()) == "TRT") {
      entries += t.size();
      bands.push_back({{"table", t.path()}, {"entries", t.size()}, {"beta_range", t.attributes.value("beta_band", json::object()).value("range", json::array())}});
    }
  const double beta_lo = c.np_beta_bands.front().lo(), beta_hi = c.np_beta_bands.back().hi();
  const std::size_t calls = s.quick ? (1u << 18) : (1u << 21);
  const std::string load_before = load_average();
  json rows = json::array();
  for (const bool in_cache : {true, false}) {
    const Points pts = draw(in_cache ? 256 : (1u << 20), beta_lo, beta_hi, c.np_axes->at(1).hi, c.np_axes->at(2).hi, 11);
    json r = {{"cache", in_cache ? "in cache (256 points repeated)" : "out of cache (2^20 random points)"}};
    r["float"] = measure<float>(set, pts, calls, s.repeats);
    r["double"] = measure<double>(set, pts, calls, s.repeats);
    rows.push_back(r);
  }
  const std::string load_after = load_average();
  const std::size_t error_points = s.quick ? 4000 : 40000;
  log(s.quiet, "bands: sampled error of the TRT band tables, %zu points each, cubic and linear along beta and sigma_a\n", error_points);
  const auto te = clock_type::now();
  const json errors = band_errors(set, error_points, s.max_threads);
  const double error_s = seconds_since(te);
  const std::size_t energy_entries = set.find("np/energy_TRT")->size();
  json out = {{"config", config}, {"bake_seconds", bake_s}, {"threads", s.max_threads},
              {"entries_per_lobe", entries}, {"energy_factor_entries_per_lobe", energy_entries}, {"bands", bands}, {"lookups", rows},
              {"load_average_before", load_before}, {"load_average_after", load_after}, {"timing", "thread CPU time, best of repeats, one thread"},
              {"sampled_error", errors}, {"sampled_error_seconds", error_s},
              {"note", "banded: band of beta, cubic on every axis, times the energy factor (HairTables::np_value); banded linear beta sigma_a: "
                       "the same with beta and sigma_a linear (64 taps); plain: band 0's table read with every axis linear, no factor (FixedView); "
                       "sampled error: measure_sampled_error as validate-hair-luts measures (seed FNV-1a of the table path)"}};
  std::ostringstream md;
  md << "# N_p in beta bands: lookup cost\n\n";
  if (!load_before.empty()) md << "Load average (1, 5, 15 min) before the timings: " << load_before << "; after: " << load_after << ". Thread CPU time, best of repeats, one thread.\n\n";
  md << "The banded layout (bands.cpp): " << entries << " N_p entries per lobe in "
     << bands.size() << " bands (and " << energy_entries << " in the lobe's energy factor table), baked in " << fmt(bake_s) << " s on " << s.max_threads << " threads.\n\n"
     << "| points | arithmetic | banded cubic x factor | ratio | banded, linear along beta and sigma_a, x factor | ratio | plain multilinear |\n"
     << "|---|---|---|---|---|---|---|\n";
  std::ostringstream csv;
  csv << "cache,arithmetic,ns_banded,ns_banded_linear_beta_sigma,ns_plain,ratio,ratio_linear_beta_sigma\n";
  for (const json& r : rows)
    for (const char* a : {"float", "double"}) {
      md << "| " << r["cache"].get<std::string>() << " | " << a << " | " << fmt(r[a]["ns_banded_cubic_factor"].get<double>()) << " ns | "
         << fmt(r[a]["ratio"].get<double>()) << " | " << fmt(r[a]["ns_banded_linear_beta_sigma_factor"].get<double>()) << " ns | "
         << fmt(r[a]["ratio_linear_beta_sigma"].get<double>()) << " | " << fmt(r[a]["ns_plain_multilinear"].get<double>()) << " ns |\n";
      csv << '"' << r["cache"].get<std::string>() << "\"," << a << ',' << r[a]["ns_banded_cubic_factor"] << ','
          << r[a]["ns_banded_linear_beta_sigma_factor"] << ',' << r[a]["ns_plain_multilinear"] << ',' << r[a]["ratio"] << ','
          << r[a]["ratio_linear_beta_sigma"] << '\n';
    }
  md << "\nSampled error of the TRT band tables (validate-hair-luts' measure: " << error_points
     << " random points per table, relative to the local peak), as baked (cubic on every axis) and read linearly along beta and sigma_a:\n\n"
     << "| table | beta range | cubic worst | cubic p99 | linear beta, sigma_a worst | linear beta, sigma_a p99 |\n|---|---|---|---|---|---|\n";
  for (const json& e : errors)
    md << "| " << e["table"].get<std::string>() << " | " << fmt(e["beta_range_deg"][0].get<double>()) << "-" << fmt(e["beta_range_deg"][1].get<double>())
       << " deg | " << fmt(e["cubic_worst"].get<double>()) << " | " << fmt(e["cubic_p99"].get<double>()) << " | "
       << fmt(e["linear_beta_sigma_worst"].get<double>()) << " | " << fmt(e["linear_beta_sigma_p99"].get<double>()) << " |\n";
  write_file(s, "bands.json", out.dump(2) + "\n");
  write_file(s, "bands.csv", csv.str());
  write_file(s, "bands.md", md.str());
  return out;
}

}  // namespace bench
