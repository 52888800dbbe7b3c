// Section "per material": Tungsten's precompute (baseline_tungsten.cpp) against hairlut's
// per-material bake (hairlut/physics/material_np.hpp), one thread, the same material and β, on the
// baseline's own layout (64 cos θd = y/63 × 64 φ = 2πx/63, both ends present) and on hairlut's
// (64 cos θd cell centres × 64 φ cell centres over (0, π)); accuracy of both against the adaptive
// reference; a floor model of hairlut's work (nodes × terms × channels at measured unit costs)
// next to the measurement.
#include <cmath>
#include <hairlut/util/angles.hpp>
#include <hairlut/physics/azimuthal_np.hpp>
#include <hairlut/physics/material_np.hpp>
#include <hairlut/physics/melanin.hpp>
#include <hairlut/util/vector_math.hpp>
#include <sstream>

#include "baseline_tungsten.hpp"
#include "bench_common.hpp"

namespace bench {

using namespace hairlut;

namespace {

struct Layout {
  std::string name, description;
  std::vector<double> thetas, phis;
};

Layout tungsten_layout() {
  Layout l{"tungsten", "64 cos(theta_d) = y/63 x 64 phi = 2 pi x/63 (Tungsten's, both ends present)", {}, {}};
  for (int y = 0; y < 64; ++y) l.thetas.push_back(std::acos(y / 63.0));
  for (int x = 0; x < 64; ++x) l.phis.push_back(kTwoPi * x / 63.0);
  return l;
}

Layout hairlut_layout() {
  Layout l{"hairlut", "64 cos(theta_d) cell centres x 64 phi cell centres over (0, pi) (phi even)", {}, {}};
  for (int t = 0; t < 64; ++t) l.thetas.push_back(std::acos((t + 0.5) / 64.0));
  for (int j = 0; j < 64; ++j) l.phis.push_back((j + 0.5) * kPi / 64.0);
  return l;
}

// One hairlut per-material bake, rules included (as Tungsten builds its rule inside).
void hairlut_material(const Layout& l, const std::array<double, 3>& sigma, double beta, double tol, std::vector<double>& out) {
  MaterialNpRequest r{1.55, AbsorptionPath::chord, {beta, beta, beta}, {sigma[0], sigma[1], sigma[2]}, l.thetas, l.phis, tol};
  const MaterialNp np(std::move(r));
  const std::size_t per = 3 * 3 * l.phis.size();
  out.resize(l.thetas.size() * per);
  std::vector<double> v;
  for (std::size_t t = 0; t < l.thetas.size(); ++t) {
    np.evaluate(t, v);
    std::copy(v.begin(), v.end(), out.begin() + static_cast<std::ptrdiff_t>(t * per));
  }
}

// Nanoseconds per exponential (hairlut::exp_in_place over an array, what MaterialNp calls), per
// std::asin call over an array, and per multiply–add of the spreading kernel (b[j] += a · w[j]
// over windows of 8 at moving, non-overlapping offsets), each timed on its own over arrays that
// stay in cache.
struct UnitCosts {
  double exp_ns, asin_ns, madd_ns;
};

UnitCosts unit_costs() {
  const std::size_t n = 4096;
  std::vector<double> x(n), y(n);
  auto time_it = [&](auto&& f, double per) {
    std::vector<double> t;
    for (int r = 0; r < 15; ++r) {
      const double c0 = thread_cpu_seconds();
      for (int k = 0; k < 20; ++k) f();
      t.push_back((thread_cpu_seconds() - c0) / 20.0 / per * 1e9);
    }
    return minimum(t);
  };
  volatile double sink = 0.0;
  UnitCosts c{};
  for (std::size_t i = 0; i < n; ++i) x[i] = -20.0 * static_cast<double>(i) / n;
  c.exp_ns = time_it([&] {
    std::copy(x.begin(), x.end(), y.begin());  // a copy per pass (about 0.1 ns per element)
    exp_in_place(y);
    sink = y[7];
  }, n);
  for (std::size_t i = 0; i < n; ++i) x[i] = 0.6 * static_cast<double>(i) / n;
  c.asin_ns = time_it([&] { for (std::size_t i = 0; i < n; ++i) y[i] = std::asin(x[i]); sink = y[7]; }, n);
  std::vector<double> buf(2048 + 8, 0.0), win(8, 0.5);
  c.madd_ns = time_it([&] {
    for (std::size_t i = 0; i < 256; ++i) {
      double* b = buf.data() + (i * 8 % 2048) + (i & 1);  // windows that do not overlap their neighbours
      const double a = 1e-3 * static_cast<double>(i);
#pragma omp simd
      for (std::size_t j = 0; j < 8; ++j) b[j] += a * win[j];
    }
    sink = buf[5];
  }, 256.0 * 8);
  (void)sink;
  return c;
}

// The floor model of MaterialNp per material: per θd, on its m nodes, one asin and K exp (T); R
// spread over fixed windows (run multiply–adds per node); every other spread lobe two exp and
// 2R + 1 window points (one multiply each, counted as multiply–adds) and K × run multiply–adds
// per node. Fourier lobes are left out of the time (their sums run in registers, far faster than
// the spreading kernel's multiply–add measured here) and reported as counts: (N + 1) terms × m
// nodes × channels, and channels × points × (N + 1) for the cosine sums.
double floor_model_ns(const MaterialNp& plan, std::size_t thetas, std::size_t K, const UnitCosts& u) {
  double ns = 0.0;
  for (std::size_t t = 0; t < thetas; ++t) {
    const double m = plan.nodes_at(t);
    ns += m * (u.asin_ns + static_cast<double>(K) * u.exp_ns);
    for (int p = 0; p < 3; ++p) {
      const double planes = p == 0 ? 1.0 : static_cast<double>(K);
      if (plan.spreads(t, p)) {
        const double W = plan.window_of(p), run = std::max(8.0, std::ceil(W / 4.0) * 4.0);
        ns += p == 0 ? m * run * u.madd_ns : m * (2.0 * u.exp_ns + (W + planes * run) * u.madd_ns);
      }
    }
  }
  return ns;
}

}  // namespace

json bench_per_material(const Settings& st) {
  const Rgb s = melanin_sigma_a_rgb(0.8, 0.2);
  const std::array<double, 3> sigma = {s.r, s.g, s.b};
  const double tol = 1e-10;
  std::vector<double> betas_deg = {2, 5, 10, 20, 30};
  if (st.quick) betas_deg = {2, 30};
  const int runs = st.quick ? 3 : 9;
  const std::vector<Layout> layouts = {tungsten_layout(), hairlut_layout()};
  const UnitCosts unit = unit_costs();
  json rows = json::array();
  std::ostringstream csv, md;
  csv << "beta_deg,layout,baseline_ms,hairlut_ms,ratio,speedup,baseline_max_err_of_peak,hairlut_max_err_of_peak,nodes,window,floor_model_ms\n";
  md << "| β | layout | Tungsten precompute (re-implementation) | hairlut | speed-up | baseline error / peak | hairlut error / peak | floor model |\n"
        "|---|---|---|---|---|---|---|---|\n";
  for (double bd : betas_deg) {
    const double beta = radians(bd);
    const TungstenMaterial tm{1.55f, {static_cast<float>(sigma[0]), static_cast<float>(sigma[1]), static_cast<float>(sigma[2])}, static_cast<float>(beta)};
    for (const Layout& l : layouts) {
      log(st.quiet, "per material: beta %g deg, %s layout ...\n", bd, l.name.c_str());
      TungstenTables base;
      std::vector<double> ours;
      std::vector<double> tb, th;
      std::vector<double> wb, wh;
      for (int i = 0; i < runs; ++i) {  // alternating, so that both see the same machine
        auto t0 = clock_type::now();
        double c0 = thread_cpu_seconds();
        tungsten_precompute(tm, base);
        tb.push_back(thread_cpu_seconds() - c0);
        wb.push_back(seconds_since(t0));
        t0 = clock_type::now();
        c0 = thread_cpu_seconds();
        hairlut_material(l, sigma, beta, tol, ours);
        th.push_back(thread_cpu_seconds() - c0);
        wh.push_back(seconds_since(t0));
      }
      // Errors at sampled nodes against the adaptive reference, relative to each lobe's peak.
      double base_err = 0.0, our_err = 0.0;
      const std::size_t nphi = l.phis.size();
      const Layout tl = tungsten_layout();
      for (int p = 0; p < 3; ++p) {
        for (int which = 0; which < (l.name == "tungsten" ? 2 : 1); ++which) {
          // which 0: hairlut on this layout; 1: the baseline (always on its own layout)
          const Layout& ll = which == 0 ? l : tl;
          std::vector<double> ref, got;
          double peak = 0.0;
          for (std::size_t t = 3; t < 64; t += st.quick ? 20 : 8)
            for (std::size_t j = 0; j < nphi; j += 2)
              for (std::size_t k = 0; k < 3; ++k) {
                ref.push_back(azimuthal_np_reference(AttenuationSlice(1.55, ll.thetas[t], sigma[k]), p, beta, ll.phis[j], 1e-12).value[0]);
                peak = std::max(peak, ref.back());
                got.push_back(which == 0 ? ours[t * 9 * nphi + (static_cast<std::size_t>(p) * 3 + k) * nphi + j]
                                         : static_cast<double>(base.lobe[static_cast<std::size_t>(p)].value[(t * 64 + j) * 3 + k]));
              }
          double e = 0.0;
          for (std::size_t q = 0; q < ref.size(); ++q) e = std::max(e, std::abs(got[q] - ref[q]) / peak);
          (which == 0 ? our_err : base_err) = std::max(which == 0 ? our_err : base_err, e);
        }
      }
      // The floor model next to the measurement (floor_model_ns).
      MaterialNpRequest r{1.55, AbsorptionPath::chord, {beta, beta, beta}, {sigma[0], sigma[1], sigma[2]}, l.thetas, l.phis, tol};
      const MaterialNp plan(std::move(r));
      const double model_ns = floor_model_ns(plan, l.thetas.size(), 3, unit);
      int nodes = 0, spread_rows = 0;
      for (std::size_t t = 0; t < l.thetas.size(); ++t) {
        nodes = std::max(nodes, plan.nodes_at(t));
        for (int p = 0; p < 3; ++p) spread_rows += plan.spreads(t, p);
      }
      const int fourier_lobe_thetas = 3 * static_cast<int>(l.thetas.size()) - spread_rows;
      std::string how = std::to_string(nodes) + " nodes";
      if (spread_rows) how += ", window " + std::to_string(plan.window_of(0)) + " points";
      if (fourier_lobe_thetas)
        how += "; not timed: " + std::to_string(fourier_lobe_thetas) + " (theta_d, lobe) in Fourier form, " + std::to_string(plan.fourier_terms_of(2) + 1) +
               " terms x " + std::to_string(nodes) + " nodes x 3 channels each";
      json row = {{"beta_deg", bd},
                  {"layout", l.name},
                  {"layout_description", l.description},
                  {"baseline_ms_min", minimum(tb) * 1e3},
                  {"baseline_ms_median", median(tb) * 1e3},
                  {"hairlut_ms_min", minimum(th) * 1e3},
                  {"hairlut_ms_median", median(th) * 1e3},
                  {"baseline_wall_ms_min", minimum(wb) * 1e3},
                  {"hairlut_wall_ms_min", minimum(wh) * 1e3},
                  {"ratio", minimum(th) / minimum(tb)},
                  {"speedup", minimum(tb) / minimum(th)},
                  {"baseline_max_err_of_peak", base_err},
                  {"hairlut_max_err_of_peak", our_err},
                  {"hairlut_tolerance", tol},
                  {"nodes", nodes},
                  {"window_points", plan.window_of(0)},
                  {"fourier_terms", plan.fourier_terms_of(0) + 1},
                  {"fourier_lobe_thetas", fourier_lobe_thetas},
                  {"floor_model_ms", model_ns * 1e-6},
                  {"floor_model", how}};
      rows.push_back(row);
      csv << bd << ',' << l.name << ',' << row["baseline_ms_min"] << ',' << row["hairlut_ms_min"] << ',' << row["ratio"] << ',' << row["speedup"] << ','
          << base_err << ',' << our_err << ',' << nodes << ',' << plan.window_of(0) << ',' << model_ns * 1e-6 << "\n";
      md << "| " << bd << "° | " << l.name << " | " << fmt(minimum(tb) * 1e3) << " ms | " << fmt(minimum(th) * 1e3) << " ms | "
         << fmt(minimum(tb) / minimum(th)) << "× | " << (l.name == "tungsten" ? fmt(base_err, 2) : std::string("—")) << " | " << fmt(our_err, 2)
         << " | " << fmt(model_ns * 1e-6) + " ms (" + how + ")" << " |\n";
    }
  }
  const TungstenCounts n = tungsten_counts({1.55f, {0.0f, 0.0f, 0.0f}, static_cast<float>(radians(2.0))});
  json counts = {{"rule_newton_steps", n.rule_newton_steps},   {"detector_gaussians_beta_2deg", n.detector_gaussians},
                 {"row_asin", n.row_asin},                     {"row_cos", n.row_cos},
                 {"row_exp", n.row_exp},                       {"row_fresnel", n.row_fresnel},
                 {"node_visits", n.node_visits},               {"detector_lookups", n.detector_lookups},
                 {"colour_multiply_adds", n.colour_multiply_adds}, {"table_entries", n.table_entries}};
  json unit_json = {{"exp_ns", unit.exp_ns}, {"asin_ns", unit.asin_ns}, {"window_multiply_add_ns", unit.madd_ns}};
  const std::string model_text =
      "floor model (floor_model_ns): per theta_d, m nodes x (asin + 3 exp); R spread over fixed windows (run multiply-adds per node); "
      "TT, TRT spread: per node 2 exp + (2R + 1) window points + 3 x run multiply-adds; at the unit costs measured in the same run; "
      "Fourier lobes counted, not timed (their sums run in registers, faster than the spreading multiply-add)";
  json result = {{"machine", st.machine},
                 {"material", "sigma_a of eumelanin 0.8 + pheomelanin 0.2 (d'Eon's cross-sections), eta 1.55, chord path, one beta for R, TT, TRT"},
                 {"baseline", "Tungsten HairBcsdf::precomputeAzimuthalDistributions re-implemented operation for operation "
                              "(tools/bench-hair-luts/baseline_tungsten.cpp; tunabrain/tungsten 88ea020): 140-point Gauss-Legendre in h "
                              "built inside, float, three 2048-sample detector tables of one beta, lookups shared by RGB, sampling CDFs"},
                 {"hairlut", "hairlut::MaterialNp (lib/src/physics/material_np.cpp), tolerance 1e-10 of the lobe peak, rules built inside, one thread"},
                 {"timing", "CPU time of the one thread (CLOCK_THREAD_CPUTIME_ID; wall times also recorded), minimum (and median) of " +
                                std::to_string(runs) + " alternating runs of each"},
                 {"error", "max |value - adaptive reference (1e-12)| / lobe peak over every 8th theta_d row from row 3, every 2nd phi, RGB, R/TT/TRT"},
                 {"baseline_operation_counts", counts},
                 {"unit_costs", unit_json},
                 {"floor_model", model_text},
                 {"rows", rows}};
  md << "\nBaseline operation counts per material (β = 2°): " << counts.dump() << "\n\nUnit costs (ns): " << unit_json.dump() << "\n\n" << model_text << ".\n";
  write_file(st, "per-material.json", result.dump(2) + "\n");
  write_file(st, "per-material.csv", csv.str());
  write_file(st, "per-material.md", md.str());
  return result;
}

}  // namespace bench
