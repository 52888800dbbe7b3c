// The renderer runtime on the tables of one material (HairScattering over materials/<name>;
// material_scattering.hpp), tested as pbrt-v4 and Mitsuba 3 test their hair BSDFs (peer_hair_tests.hpp
// names the files and commits), with their counts and tolerances.
//
// A material's tables fix its roughness, so each (β_m, β_n) pair of a peer's loop is a material of
// its own: the sets below are baked in memory from the shipped per-show example config, untilted
// and white (σa = 0) where the peers test energy, with M_p on 0.4° nodes so that the tables' own
// normalisation error (a 4.6° lobe read linearly: 9.6e-4 on 0.5° nodes at θo beyond 89°, 6e-4
// here) and the lobe energies' (up to 7e-5 near grazing) stay below Mitsuba's 1e-3 together. The peers' roughness
// maps as in peer_hair_tests.hpp, clamped to [2°, 45°] as the generic tables' β axis is.
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/bake/table_truth.hpp>
#include <hairlut/tables/hair_views.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "catch.hpp"
#include "peer_hair_tests.hpp"

using namespace hairlut;
using Runtime = sampler::HairScattering<float>;
using peer::average;
using peer::Rng;
using peer::uniform_sphere;

namespace {

constexpr double kPiM = peer::kPi;

double degrees_of(double rad) { return rad * 180.0 / kPiM; }
std::string name_of(double bm, double bn) {
  std::ostringstream s;
  s << "m" << bm << "-n" << bn;
  return s.str();
}

// The per-show example config with the given materials: peer roughness pairs (β_m, β_n), one grey
// σa, tilts as shipped or none.
TableSet bake_materials(const std::vector<std::pair<double, double>>& pairs, double sigma_a, bool tilted) {
  std::ifstream in(std::string(HAIRLUT_SOURCE_DIR) + "/tables/configs/show-example.json");
  nlohmann::json j = nlohmann::json::parse(in);
  if (!tilted) j["lobes"].erase("tilt_deg");
  // θd on the show's own 256 nodes: the tables store N_p of the lobes p ≥ 1 over cos²θd up to 90°,
  // so the lobes' energies sum to 1 between nodes only to the interpolation error of R's, which
  // falls as cos²θd, in the last cells (about 30 h²/4 for a cos θd step h: 1.2e-4 here, 1.9e-3 on
  // a quarter of the nodes, above Mitsuba's 1e-3 per lane).
  j["tables"]["mp"]["axes"]["theta_i"]["count"] = 451;
  j["tables"]["mp"]["axes"]["theta_r"]["count"] = 451;
  j["scene"]["materials"] = nlohmann::json::array();
  for (const auto& [bm, bn] : pairs) {
    const double m = std::clamp(degrees_of(peer::pbrt_beta_m(bm)), 2.0, 45.0), n = std::clamp(degrees_of(peer::pbrt_beta_n(bn)), 2.0, 45.0);
    j["scene"]["materials"].push_back({{"name", name_of(bm, bn)},
                                       {"sigma_a", {sigma_a, sigma_a, sigma_a}},
                                       {"beta_deg", {{"R", m}, {"residual", m}}},
                                       {"beta_n_deg", {{"R", n}, {"residual", n}}}});
  }
  j["output"]["formats"] = {"hdf5"};
  j["output"]["directory"] = ".";
  BakeOptions options;
  options.threads = 2;
  return bake(parse_config(j, "materials.json", std::string(HAIRLUT_SOURCE_DIR) + "/tables/configs"), options);
}

// The peers' loops, each pair a material; baked once per loop.
std::vector<std::pair<double, double>> grid(std::vector<double> ms, std::vector<double> ns) {
  std::vector<std::pair<double, double>> g;
  for (double m : ms)
    for (double n : ns) g.emplace_back(m, n);
  return g;
}
// The baked materials; each one's runtime is built when asked for, one at a time (the runtimes of
// all 25 at once would hold about 0.8 GB of sampling rows).
struct MaterialSet {
  TableSet set;
  std::vector<std::pair<double, double>> pairs;
  MaterialSet(const std::vector<std::pair<double, double>>& p, double sigma_a, bool tilted) : set(bake_materials(p, sigma_a, tilted)), pairs(p) {}
  const Runtime& operator()(double bm, double bn) const {
    if (!rt_ || key_ != std::make_pair(bm, bn)) {
      rt_.reset();
      rt_.emplace(hair_scattering<float>(set, "materials/" + name_of(bm, bn)));
      key_ = {bm, bn};
    }
    return *rt_;
  }

 private:
  mutable std::pair<double, double> key_{-1.0, -1.0};
  mutable std::optional<Runtime> rt_;
};
// pbrt's WhiteFurnace and WhiteFurnaceSampled grid (β_m, β_n = 0.1 … 0.9 step 0.2).
const MaterialSet& pbrt_white() {
  static const MaterialSet s(grid({0.1, 0.3, 0.5, 0.7, 0.9}, {0.1, 0.3, 0.5, 0.7, 0.9}), 0.0, false);
  return s;
}
// The shipped per-show example: tilted, coloured materials as a show bakes them.
const TableSet& show_tables() {
  static const TableSet set = [] {
    std::ifstream in(std::string(HAIRLUT_SOURCE_DIR) + "/tables/configs/show-example.json");
    nlohmann::json j = nlohmann::json::parse(in);
    j["output"]["formats"] = {"hdf5"};
    j["output"]["directory"] = ".";
    BakeOptions options;
    options.threads = 2;
    return bake(parse_config(j, "show-example.json", std::string(HAIRLUT_SOURCE_DIR) + "/tables/configs"), options);
  }();
  return set;
}
const std::vector<std::string>& show_materials() {
  static const std::vector<std::string> names = {"hero-blonde", "hero-brunette", "crowd-black", "white-beard"};
  return names;
}

// S of a material composed from each of its tables as the generic Table::sample reads it (each
// value times the grazing factor it was stored over, for the channel's σa).
void reference_s(const TableSet& set, const std::string& group, double to, double ti, double phi, double* rgb) {
  rgb[0] = rgb[1] = rgb[2] = 0.0;
  std::vector<std::string> lobes;
  for (const auto& l : set.metadata.at("lobes")) lobes.push_back(l.get<std::string>());
  lobes.push_back("residual");
  for (const std::string& l : lobes) {
    const Table* m = set.find(group + "/mp_" + l);
    const Table* n = set.find(group + "/np_" + l);
    if (!m || !n) continue;
    const double mval = m->sample({ti, to});
    for (int c = 0; c < 3; ++c) {
      std::vector<double> xn = {static_cast<double>(c), std::fabs(0.5 * (to - ti)), std::fabs(phi)};
      if (n->axes.size() == 2) xn.pop_back();  // the residual: uniform in φ
      rgb[c] += mval * n->sample(xn);
    }
  }
}

}  // namespace

TEST_CASE("MaterialScattering: eval is the material's S as TableView reads each table", "[scattering][material]") {
  const TableSet& set = show_tables();
  Rng rng(3);
  const sampler::Fiber f;
  for (const std::string& name : show_materials()) {
    const Runtime rt = hair_scattering<float>(set, "materials/" + name);
    REQUIRE(rt.valid());
    REQUIRE(rt.material());
    double worst = 0.0;
    for (int i = 0; i < 3000; ++i) {
      // Beyond the axes too: θd past the last node, φ past ±π.
      const double to = (2.0 * rng() - 1.0) * 0.5 * kPiM, ti = (2.0 * rng() - 1.0) * 0.5 * kPiM, phi = (2.0 * rng() - 1.0) * 1.5 * kPiM;
      double got[3], want[3];
      rt.eval(f, to, ti, phi, got);
      reference_s(set, "materials/" + name, to, ti, std::remainder(phi, 2.0 * kPiM), want);
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(got[c] - want[c]) / std::max(1e-6, want[c]));
    }
    INFO(name << ": worst relative difference " << worst);
    CHECK(worst < 1e-12);
  }
}

TEST_CASE("MaterialScattering: N_p up to theta_d = 90 deg against the exact N_p, and S as the tables give it there", "[scattering][material]") {
  // The show's θd axis reaches 90°, where N_p of TT, TRT, TRRT and the residual vanish (as cos²θd,
  // and the residual as cos θd at σa = 0): the tables store N_p over its grazing factor. Against
  // the validator's reference over the last half degree, relative to the local peak along φ, with
  // the show's N_p threshold (5e-2) as the bound a user relies on; and the runtime's S there is the
  // tables' (TableView times the factor), to rounding.
  const TableSet& set = show_tables();
  const auto rule = std::make_shared<const GaussLegendreRule>(1024);
  const TruthModel model{1.55, AbsorptionPath::chord, 4, nullptr, nullptr};
  const std::vector<double> degs = {89.5, 89.6, 89.8, 89.9, 89.95, 89.99, 89.999, 90.0};
  for (const std::string& name : show_materials()) {
    for (const std::string lobe : {"TT", "TRT", "TRRT", "residual"}) {
      const Table* t = set.find("materials/" + name + "/np_" + lobe);
      REQUIRE(t);
      CHECK(!t->grazing_factor().none());
      const auto truth = table_truth(*t, model, rule);
      REQUIRE(truth);
      double worst = 0.0;
      for (int c = 0; c < 3; ++c)
        for (double deg : degs) {
          const double td = std::min(deg * kPiM / 180.0, 0.5 * kPiM);
          std::vector<double> x = {static_cast<double>(c), td};
          if (t->axes.size() == 3) x.push_back(0.0);
          const PointFunction exact = truth->make(x);
          // The validator's denominator: the peak along φ (N_p), the value itself (the residual),
          // with its floors.
          double peak = std::max(truth->absolute_floor, truth->white_floor * std::fabs(truth->make_white(x)(x)));
          std::vector<std::pair<double, double>> vals;
          for (int k = 0; k <= (t->axes.size() == 3 ? 360 : 0); ++k) {
            if (t->axes.size() == 3) x[2] = kPiM * k / 360.0;
            const double e = exact(x);
            peak = std::max(peak, std::fabs(e));
            vals.emplace_back(t->sample(x), e);
          }
          for (const auto& [got, want] : vals)
            if (peak > 0.0) worst = std::max(worst, std::fabs(got - want) / peak);
        }
      INFO(name << " " << lobe << ": worst error over theta_d 89.5-90 deg, of the local peak, " << worst);
      CHECK(worst < 5e-2);
    }
    const Runtime rt = hair_scattering<float>(set, "materials/" + name);
    const sampler::Fiber f;
    double worst = 0.0;
    for (double to_deg : {89.0, 89.7, 89.97, 90.0})
      for (double ti_deg : {-89.0, -89.6, -89.95, -90.0})
        for (double phi : {0.0, 1.0, 2.5, kPiM}) {
          const double to = to_deg * kPiM / 180.0, ti = ti_deg * kPiM / 180.0;
          double got[3], want[3];
          rt.eval(f, to, ti, phi, got);
          reference_s(set, "materials/" + name, to, ti, phi, want);
          for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(got[c] - want[c]) / std::max(1e-20, std::fabs(want[c])));
        }
    INFO(name << ": runtime against the tables near grazing, worst relative difference " << worst);
    CHECK(worst < 1e-9);
  }
}

TEST_CASE("MaterialScattering: pdf integrates to one and albedo() is the integral of S", "[scattering][material]") {
  // Midpoint rule in (θi, φ) on 1/16° × 1/8° cells, θo up to 0.05° from the poles.
  const TableSet& set = show_tables();
  const sampler::Fiber f;
  for (const std::string& name : {std::string("white-beard"), std::string("hero-brunette")}) {
    const Runtime rt = hair_scattering<float>(set, "materials/" + name);
    for (double deg : {-89.95, -70.0, 0.0, 33.0, 89.95}) {
      const double to = deg * kPiM / 180.0, wo[3] = {std::sin(to), std::cos(to), 0.0};
      const Runtime::ShadingPoint sp = rt.at(f, wo);
      REQUIRE(sp.valid());
      const int nt = 2880, np = 1440;
      double p = 0.0, s = 0.0;
      for (int a = 0; a < nt; ++a)
        for (int b = 0; b < np; ++b) {
          const double ti = -0.5 * kPiM + (a + 0.5) * kPiM / nt, ph = -kPiM + 2.0 * kPiM * (b + 0.5) / np;
          double rgb[3];
          rt.eval(f, to, ti, ph, rgb);
          p += sp.pdf(ti, ph) * std::cos(ti);
          s += average(rgb) * std::cos(ti);
        }
      p *= (kPiM / nt) * (2.0 * kPiM / np), s *= (kPiM / nt) * (2.0 * kPiM / np);
      INFO(name << " theta_o " << deg << ": integral of pdf " << p << ", of S " << s << ", albedo() " << sp.albedo());
      CHECK(p == Approx(1.0).epsilon(1e-3));
      CHECK(sp.albedo() == Approx(s).epsilon(2e-3));
    }
  }
}

TEST_CASE("MaterialScattering: pbrt-v4 Hair.WhiteFurnace and Hair.WhiteFurnaceSampled", "[scattering][material]") {
  const MaterialSet& m = pbrt_white();
  const sampler::Fiber f;
  Rng rng(7);
  double wo[3];
  uniform_sphere(rng(), rng(), wo);
  for (double bm = 0.1; bm < 1.0; bm += 0.2)
    for (double bn = 0.1; bn < 1.0; bn += 0.2) {
      const Runtime& rt = m(std::round(bm * 10) / 10, std::round(bn * 10) / 10);
      const auto [uniform, sampled] = peer::white_furnaces(rt, f, wo, rng, (bm < 0.5 || bn < 0.5) ? 100000 : 20000);
      INFO("pbrt beta_m " << bm << " beta_n " << bn << ": uniform " << uniform << ", sampled " << sampled);
      CHECK(uniform >= 0.95);
      CHECK(uniform <= 1.05);
      CHECK(sampled >= 0.99);
      CHECK(sampled <= 1.01);
    }
}

TEST_CASE("MaterialScattering: pbrt-v4 Hair.SamplingWeights, every sample's weight of a white fiber", "[scattering][material]") {
  const MaterialSet m(grid({0.1, 0.3, 0.5, 0.7, 0.9}, {0.4, 0.6, 0.8}), 0.0, false);
  Rng rng(13);
  peer::WeightSpread r;
  for (const auto& [bm, bn] : m.pairs) peer::sampling_weights(m(bm, bn), sampler::Fiber(), rng, 10000, false, r);
  INFO(r.total << " samples, weights in [" << r.lo << ", " << r.hi << "]");
  CHECK(r.total == 150000);
  CHECK(r.outside == 0);
}

TEST_CASE("MaterialScattering: pbrt-v4 Hair.SamplingConsistency, importance and uniform estimates agree", "[scattering][material]") {
  const MaterialSet m(grid({0.2, 0.4, 0.6, 0.8}, {0.4, 0.6, 0.8}), 0.25, false);
  Rng rng(17);
  for (const auto& key : m.pairs) {
    double wo[3];
    uniform_sphere(rng(), rng(), wo);
    const auto [importance, uniform] = peer::sampling_consistency(m(key.first, key.second), sampler::Fiber(), wo, rng, 64 * 1024);
    INFO("pbrt beta_m " << key.first << " beta_n " << key.second << ": importance " << importance << " uniform " << uniform);
    CHECK(std::fabs(importance - uniform) / uniform < 0.05);
  }
}

TEST_CASE("MaterialScattering: pbrt-v4 Hair.HOnTheEdge and the frame's edges give finite values", "[scattering][material]") {
  const peer::EdgeChecks r = peer::h_on_the_edge(pbrt_white()(0.1, 0.1), sampler::Fiber());
  INFO(r.failures << " failed, the first: " << r.first);
  CHECK(r.failures == 0);
}

TEST_CASE("MaterialScattering: Mitsuba 3 test04_sample_numeric, every lane's luminance weight within 1e-3", "[scattering][material]") {
  std::vector<std::pair<double, double>> pairs;
  for (int a = 0; a < 5; ++a)
    for (int b = 0; b < 5; ++b) pairs.emplace_back(0.1 + 0.89 * a / 4.0, 0.1 + 0.89 * b / 4.0);
  const MaterialSet m(pairs, 0.0, false);
  Rng rng(0);
  peer::LaneWeights w;
  for (const auto& p : pairs) peer::sample_numeric(m(p.first, p.second), sampler::Fiber(), rng, 100000, w);
  INFO(w.lanes << " lanes, worst |w - 1| " << w.worst);
  CHECK(w.bad == 0);
}

TEST_CASE("MaterialScattering: Mitsuba 3 test06_chi2 on the shipped show's materials", "[scattering][material]") {
  // Mitsuba's χ² (peer_hair_tests.hpp): 301 × 150 bins, 10⁶ samples, wo at Mitsuba's θ 0 and
  // 0.99 π/4 (φ π/2) for each of the four tilted, coloured materials; significance 0.01 with the
  // Šidák correction over the 8 configurations.
  const TableSet& set = show_tables();
  const sampler::Fiber f;
  const double alpha = 1.0 - std::pow(1.0 - 0.01, 1.0 / 8.0);
  int k = 0;
  for (const std::string& name : show_materials()) {
    const Runtime rt = hair_scattering<float>(set, "materials/" + name);
    for (double th : {0.0, 0.99 * kPiM / 4.0}) {
      const double wo[3] = {std::sin(th) * std::cos(kPiM / 2.0), std::sin(th) * std::sin(kPiM / 2.0), std::cos(th)};
      const peer::Chi2 r = peer::chi2_sphere<float>(rt.at(f, wo), 40 + k++, 301, 150, 1000000);
      INFO(name << " theta " << th << ": chi2 " << r.chi2 << " with " << r.dof - 1 << " dof, p " << r.p << " (alpha " << alpha << ")");
      REQUIRE(r.valid);
      CHECK(r.p > alpha);
    }
  }
}

TEST_CASE("MaterialScattering: tilted materials' weights are the albedo at wo, and pdf() is sample()'s density", "[scattering][material]") {
  // Tilted d'Eon lobes do not conserve energy (docs/conventions.md, "Tilt"): the mean weight at wo
  // is the albedo there, and the spread of the white material's weights about it measures the
  // sampling. The coloured materials' weights are each channel's S over the channels' mean density,
  // so for them the check is that pdf() and the weights are what sample() reports.
  const TableSet& set = show_tables();
  const sampler::Fiber f;
  Rng rng(29);
  for (const std::string& name : show_materials()) {
    const Runtime rt = hair_scattering<float>(set, "materials/" + name);
    int total = 0, outside1 = 0, outside10 = 0;
    double lo = 1.0, hi = 1.0;
    for (int i = 0; i < 20000; ++i) {
      double wo[3];
      uniform_sphere(rng(), rng(), wo);
      double u[3] = {rng(), rng(), rng()};
      if (i % 7 == 0) u[i % 3] = 0.0;
      const Runtime::ShadingPoint sp = rt.at(f, wo);
      const sampler::ScatteringSample s = sp.sample(u);
      REQUIRE(s.pdf > 0.0);
      // pdf() reads wi back as angles (asin, atan2): 1e-7 leaves room for that round trip on the
      // steepest lobes near grazing; a density that differs from sample()'s is off by percents.
      CHECK(sp.pdf(s.wi) == Approx(s.pdf).epsilon(1e-7));
      double rgb[3];
      rt.eval(f, wo, s.wi, rgb);
      for (int c = 0; c < 3; ++c) CHECK(s.weight[c] == Approx(rgb[c] / s.pdf).epsilon(1e-7));
      if (name != "white-beard") continue;
      const double r = average(s.weight) / sp.albedo();
      ++total, lo = std::min(lo, r), hi = std::max(hi, r);
      outside1 += !(r > 0.99 && r < 1.01), outside10 += !(r >= 0.9 && r <= 1.1);
    }
    if (name != "white-beard") continue;
    INFO(total << " samples, weight / albedo in [" << lo << ", " << hi << "], " << outside1 << " outside (0.99, 1.01)");
    CHECK(outside1 <= total / 100);
    CHECK(outside10 == 0);
  }
}

TEST_CASE("MaterialScattering: hostile values and axes", "[scattering][material][hostile]") {
  TableSet set = show_tables();
  const std::string g = "materials/hero-blonde";
  SECTION("NaN, infinite and negative values read as 0") {
    for (Table& t : set.tables)
      if (t.group == g)
        for (std::size_t k = 0; k < t.f32.size(); k += 5) t.f32[k] = k % 3 == 0 ? std::nanf("") : k % 3 == 1 ? -1e30f : INFINITY;
    const Runtime rt = hair_scattering<float>(set, g);
    REQUIRE(rt.valid());
    const sampler::Fiber f;
    Rng rng(31);
    for (int i = 0; i < 5000; ++i) {
      double wo[3], wi[3], rgb[3];
      uniform_sphere(rng(), rng(), wo);
      uniform_sphere(rng(), rng(), wi);
      rt.eval(f, wo, wi, rgb);
      for (double v : rgb) CHECK((std::isfinite(v) && v >= 0.0));
      const double u[3] = {rng(), rng(), rng()};
      const sampler::ScatteringSample s = rt.sample(f, wo, u);
      CHECK((std::isfinite(s.pdf) && s.pdf >= 0.0));
      for (double w : s.weight) CHECK((std::isfinite(w) && w >= 0.0));
    }
  }
  SECTION("an axis the runtime cannot sample exactly is refused, naming the group") {
    for (Table& t : set.tables)
      if (t.group == g && t.name == "np_R") t.axes[2].interpolation = Interpolation::cubic;
    CHECK_THROWS_WITH(hair_scattering<float>(set, g), Catch::Contains("np_R") || Catch::Contains(g));
  }
  SECTION("a missing table is named") {
    set.tables.erase(std::remove_if(set.tables.begin(), set.tables.end(), [&](const Table& t) { return t.path() == g + "/mp_TT"; }), set.tables.end());
    CHECK_THROWS_WITH(hair_scattering<float>(set, g), Catch::Contains("mp_TT"));
  }
}
