// Section "bands": the lookup cost of N_p baked in β bands (tables/configs/generic-1e-3.json,
// beta_bands.hpp) against a plain multilinear 4D lookup in the same sampler. The banded lookup is
// what a renderer does per call: pick the band of β, the band table's cubic reconstruction on every
// axis (4^4 taps), times the energy factor's 2D lookup (sampler::HairTables::np_value). The plain
// lookup reads the same band-0 table with every axis linear (2^4 taps) and no factor. Both in float
// arithmetic (R = float) and double, at the same random points (β log-uniform over the config's
// range, σa, θd, φ uniform), in cache (256 points repeated) and out of cache (2^20 points).
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/tables/beta_bands.hpp>
#include <hairlut/sampler/sampler_fibre.hpp>
#include <hairlut/sampler/sampler_fixed.hpp>

#include <cmath>
#include <random>
#include <sstream>
#include <vector>

#include "bench_common.hpp"

namespace bench {

namespace {

using namespace hairlut;

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

template <class R>
json measure(const TableSet& set, const Points& pts, std::size_t calls, int repeats) {
  // The TRT views of every band, as hair_tables fills them (the set has no M_p tables).
  sampler::HairTables<float, R> h;
  const Table& t0 = *set.find("np/TRT");
  const Table& energy = *set.find(t0.factor());
  sampler::Axis ea[2] = {energy.axes[0].view(), energy.axes[1].view()};
  h.beta_bands = static_cast<int>(set.metadata.at("np_beta_bands").size());
  for (int k = 0; k < h.beta_bands; ++k) {
    const Table& b = *set.find("np/TRT" + beta_band_suffix(k));
    sampler::Axis ba[4];
    for (int d = 0; d < 4; ++d) ba[d] = b.axes[static_cast<std::size_t>(d)].view();
    h.band_hi[k] = b.axes[0].hi;
    (k == 0 ? h.np[2] : h.np_band[k - 1][2]) = sampler::NpLobe<float, R>(b.f32.data(), ba, energy.f32.data(), ea);
  }
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
  const double linear = best_ns(calls, repeats, [&] {
    R s = 0;
    for (std::size_t i = 0, k = 0; i < calls; ++i, k = k + 1 == n ? 0 : k + 1) {
      const R x[4] = {static_cast<R>(pts.beta[k]), static_cast<R>(pts.sigma[k]), static_cast<R>(pts.theta[k]), static_cast<R>(pts.phi[k])};
      s += plain(x);
    }
    sink = sink + s;
  });
  return {{"ns_banded_cubic_factor", banded}, {"ns_plain_multilinear", linear}, {"ratio", banded / linear}};
}

}  // namespace

json bench_bands(const Settings& s) {
  const std::string config = s.source_dir + "/tables/configs/generic-1e-3.json";
  log(s.quiet, "bands: baking %s in memory\n", config.c_str());
  const BakeConfig c = load_config(config);
  BakeOptions opt;
  const auto t0 = clock_type::now();
  BakeReport report;
  const TableSet set = bake(c, opt, &report);
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
  json rows = json::array();
  for (const bool in_cache : {true, false}) {
    const Points pts = draw(in_cache ? 256 : (1u << 20), beta_lo, beta_hi, c.np_axes->at(1).hi, c.np_axes->at(2).hi, 11);
    json r = {{"cache", in_cache ? "in cache (256 points repeated)" : "out of cache (2^20 random points)"}};
    r["float"] = measure<float>(set, pts, calls, s.repeats);
    r["double"] = measure<double>(set, pts, calls, s.repeats);
    rows.push_back(r);
  }
  const std::size_t energy_entries = set.find("np/energy_TRT")->size();
  json out = {{"config", "tables/configs/generic-1e-3.json"}, {"bake_seconds", bake_s}, {"threads", s.max_threads},
              {"entries_per_lobe", entries}, {"energy_factor_entries_per_lobe", energy_entries}, {"bands", bands}, {"lookups", rows},
              {"note", "banded: band of beta, cubic on every axis, times the energy factor (HairTables::np_value); plain: band 0's "
                       "table read with every axis linear, no factor (FixedView)"}};
  std::ostringstream md;
  md << "# N_p in beta bands: lookup cost\n\n" << config.substr(s.source_dir.size() + 1) << ": " << entries << " N_p entries per lobe in "
     << bands.size() << " bands (and " << energy_entries << " in the lobe's energy factor table), baked in " << fmt(bake_s) << " s on " << s.max_threads << " threads.\n\n"
     << "| points | arithmetic | banded cubic x factor | plain multilinear | ratio |\n|---|---|---|---|---|\n";
  std::ostringstream csv;
  csv << "cache,arithmetic,ns_banded,ns_plain,ratio\n";
  for (const json& r : rows)
    for (const char* a : {"float", "double"}) {
      md << "| " << r["cache"].get<std::string>() << " | " << a << " | " << fmt(r[a]["ns_banded_cubic_factor"].get<double>()) << " ns | "
         << fmt(r[a]["ns_plain_multilinear"].get<double>()) << " ns | " << fmt(r[a]["ratio"].get<double>()) << " |\n";
      csv << '"' << r["cache"].get<std::string>() << "\"," << a << ',' << r[a]["ns_banded_cubic_factor"] << ',' << r[a]["ns_plain_multilinear"]
          << ',' << r[a]["ratio"] << '\n';
    }
  write_file(s, "bands.json", out.dump(2) + "\n");
  write_file(s, "bands.csv", csv.str());
  write_file(s, "bands.md", md.str());
  return out;
}

}  // namespace bench
