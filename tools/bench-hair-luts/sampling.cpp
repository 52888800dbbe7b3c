// bench-hair-luts, section "sampling": the cost of sampling.hpp's sample() and pdf() per call on
// the shipped default tables (one thread), and the variance of a white-furnace estimate of
// ∫ S dω with hairlut's importance sampling against uniform sampling of θr and φ at the same
// sample count. Writes sampling.json, .csv and .md.
#include <cmath>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "hairlut/io/table_io.hpp"
#include "hairlut/tables/table_sampling.hpp"

namespace bench {

json bench_sampling(const Settings& s) {
  using hairlut::sampler::FibreCoordinates;
  using hairlut::sampler::HairSampler;
  constexpr double pi = 3.14159265358979323846, deg = pi / 180.0;
  const std::string file = s.source_dir + "/tables/default/hairlut-default.h5";
  const hairlut::TableSet set = hairlut::load_tables(file);
  // Three reconstructions of the same nodes: as baked (cubic along every N_p and M_p axis: the
  // general path, a blended row per lookup), linear along every axis (the mixture fast path at
  // every lookup) and cubic along the sampled axes φ and θr only (the fast path where a node
  // slice does not dip below 0). The energy tables keep their own interpolation.
  const char* const recon_names[] = {"cubic (as baked)", "linear", "cubic along phi, theta_r only"};
  std::vector<hairlut::HairTables> recons;
  for (int r = 0; r < 3; ++r) {
    hairlut::HairTables h = hairlut::hair_tables(set, "");
    if (r > 0) {
      for (hairlut::sampler::LobeTables<float>& l : h.lobes) {
        l.np_data = l.mp_data = hairlut::sampler::AxisData();  // the stored data are those of the tables as baked
        for (hairlut::sampler::TableRef<float>* t : {&l.np, &l.mp})
          for (int d = 0; d < t->dims; ++d) {
            auto& a = const_cast<hairlut::sampler::Axis&>(t->axes[d]);
            if (a.interpolation == hairlut::sampler::Interpolation::cubic && !(r == 2 && d + 1 == t->dims))
              a.interpolation = hairlut::sampler::Interpolation::linear;
          }
      }
      h.sampler = std::make_unique<HairSampler<float>>(h.lobes.data(), static_cast<int>(h.lobes.size()));
    }
    recons.push_back(std::move(h));
  }
  // Preparing the full tables' sampler: with the sampling data stored in the file (pointers into
  // the loaded tables) against computing them (the prefix integrals and the clamp bounds).
  double prepare_stored_ms = 0.0, prepare_computed_ms = 0.0;
  {
    const hairlut::HairTables& h = recons[0];
    std::vector<hairlut::sampler::LobeTables<float>> bare = h.lobes;
    for (auto& l : bare) l.np_data = l.mp_data = hairlut::sampler::AxisData();
    double t0 = thread_cpu_seconds();
    const HairSampler<float> stored(h.lobes.data(), static_cast<int>(h.lobes.size()));
    prepare_stored_ms = (thread_cpu_seconds() - t0) * 1e3;
    t0 = thread_cpu_seconds();
    const HairSampler<float> computed(bare.data(), static_cast<int>(bare.size()));
    prepare_computed_ms = (thread_cpu_seconds() - t0) * 1e3;
    if (!stored.supported() || !computed.supported()) log(s.quiet, "sampling: the default tables cannot be sampled\n");
  }
  struct Case {
    const char* name;
    double beta, sigma_a, theta_i;
  };
  const Case cases[] = {{"narrow, white, theta_i 30 deg", 4.5 * deg, 0.0, 30.0 * deg},
                        {"medium, brown, theta_i 0", 10.0 * deg, 1.5, 0.0},
                        {"wide, white, theta_i -20 deg", 30.0 * deg, 0.0, -20.0 * deg},
                        {"grazing, white, theta_i 85 deg", 10.0 * deg, 0.0, 85.0 * deg}};
  const int calls = s.quick ? 2000 : 20000;
  const int furnace_n = s.quick ? 20000 : 200000;
  json rows = json::array();
  for (int rc = 0; rc < 3; ++rc)
  for (const Case& c : cases) {
    const hairlut::HairTables& h = recons[static_cast<std::size_t>(rc)];
    const HairSampler<float>& smp = *h.sampler;
    log(s.quiet, "sampling: %s, %s ...\n", recon_names[rc], c.name);
    const FibreCoordinates f{c.beta, c.sigma_a, 0.0};
    HairSampler<float>::Workspace ws;
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<double> us(static_cast<std::size_t>(3 * calls));
    for (double& v : us) v = u(rng);
    // sample(): the direction, its value and the mixture pdf.
    std::vector<hairlut::sampler::HairSample> drawn(static_cast<std::size_t>(calls));
    double t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) {
      const std::size_t i = static_cast<std::size_t>(3 * k);
      drawn[static_cast<std::size_t>(k)] = smp.sample(f, c.theta_i, us[i], us[i + 1], us[i + 2], ws);
    }
    const double sample_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    double sink = 0.0;
    t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) {
      const auto& d = drawn[static_cast<std::size_t>(k)];
      sink += smp.pdf(f, c.theta_i, d.theta_r, d.phi, ws);
    }
    const double pdf_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) {
      const auto& d = drawn[static_cast<std::size_t>(k)];
      sink += smp.eval(f, c.theta_i, d.theta_r, d.phi);
    }
    const double eval_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    // The same through a FibreSampler (tables blended over the fibre's β and σa once).
    t0 = thread_cpu_seconds();
    const hairlut::sampler::FibreSampler<float> fibre(h.lobes.data(), static_cast<int>(h.lobes.size()), f);
    const double prepare_us = (thread_cpu_seconds() - t0) * 1e6;
    const HairSampler<double>& fs = fibre.sampler();
    HairSampler<double>::Workspace wd;
    t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) {
      const std::size_t i = static_cast<std::size_t>(3 * k);
      sink += fs.sample(f, c.theta_i, us[i], us[i + 1], us[i + 2], wd).pdf;
    }
    const double fibre_sample_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) {
      const auto& d = drawn[static_cast<std::size_t>(k)];
      sink += fs.pdf(f, c.theta_i, d.theta_r, d.phi, wd);
    }
    const double fibre_pdf_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) {
      const auto& d = drawn[static_cast<std::size_t>(k)];
      sink += fs.eval(f, c.theta_i, d.theta_r, d.phi);
    }
    const double fibre_eval_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    // Furnace ∫ S dω: importance sampling (value / pdf) against uniform θr ∈ [−π/2, π/2] and
    // φ ∈ [−π, π] (pdf per solid angle 1 / (2π² cos θr)), the same number of samples.
    double is_sum = 0.0, is_sum2 = 0.0, un_sum = 0.0, un_sum2 = 0.0;
    for (int k = 0; k < furnace_n; ++k) {
      const auto r = fs.sample(f, c.theta_i, u(rng), u(rng), u(rng), wd);
      const double x = r.pdf > 0.0 ? r.value / r.pdf : 0.0;
      is_sum += x, is_sum2 += x * x;
      const double tr = (u(rng) - 0.5) * pi, phi = (2.0 * u(rng) - 1.0) * pi;
      const double y = fs.eval(f, c.theta_i, tr, phi) * std::cos(tr) * 2.0 * pi * pi;
      un_sum += y, un_sum2 += y * y;
    }
    const double n = furnace_n;
    const double is_mean = is_sum / n, un_mean = un_sum / n;
    const double is_var = std::max(0.0, is_sum2 / n - is_mean * is_mean), un_var = std::max(0.0, un_sum2 / n - un_mean * un_mean);
    rows.push_back({{"case", c.name},
                    {"reconstruction", recon_names[rc]},
                    {"beta_deg", c.beta / deg},
                    {"sigma_a", c.sigma_a},
                    {"theta_i_deg", c.theta_i / deg},
                    {"sample_ns", sample_ns},
                    {"pdf_ns", pdf_ns},
                    {"eval_ns", eval_ns},
                    {"fibre_prepare_us", prepare_us},
                    {"fibre_sample_ns", fibre_sample_ns},
                    {"fibre_pdf_ns", fibre_pdf_ns},
                    {"fibre_eval_ns", fibre_eval_ns},
                    {"furnace_samples", furnace_n},
                    {"furnace_importance", is_mean},
                    {"furnace_importance_stderr", std::sqrt(is_var / n)},
                    {"variance_importance", is_var},
                    {"furnace_uniform", un_mean},
                    {"furnace_uniform_stderr", std::sqrt(un_var / n)},
                    {"variance_uniform", un_var},
                    {"variance_ratio_uniform_over_importance", is_var > 0.0 ? un_var / is_var : 0.0},
                    {"sink", sink}});
  }
  json out = {{"machine", s.machine},
              {"tables", "tables/default/hairlut-default.h5"},
              {"calls_per_timing", calls},
              {"prepare_ms_stored_sampling_data", prepare_stored_ms},
              {"prepare_ms_computed_sampling_data", prepare_computed_ms},
              {"rows", rows}};
  write_file(s, "sampling.json", out.dump(2) + "\n");
  std::ostringstream csv, md;
  csv << "reconstruction,case,sample_ns,pdf_ns,eval_ns,fibre_prepare_us,fibre_sample_ns,fibre_pdf_ns,fibre_eval_ns,furnace_samples,furnace_importance,stderr_importance,furnace_uniform,stderr_uniform,variance_ratio\n";
  md << "# Sampling: cost per call and furnace variance (default tables, one thread)\n\n"
     << "| reconstruction | case | sample() ns | pdf() ns | eval() ns | FibreSampler: prepare µs | sample() ns | pdf() ns | eval() ns | furnace, importance (± 1σ) | furnace, uniform θr, φ (± 1σ) | variance uniform / importance |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const json& r : rows) {
    csv << r["reconstruction"].get<std::string>() << "," << r["case"].get<std::string>() << "," << fmt(r["sample_ns"].get<double>()) << "," << fmt(r["pdf_ns"].get<double>()) << ","
        << fmt(r["eval_ns"].get<double>()) << "," << fmt(r["fibre_prepare_us"].get<double>()) << "," << fmt(r["fibre_sample_ns"].get<double>()) << ","
        << fmt(r["fibre_pdf_ns"].get<double>()) << "," << fmt(r["fibre_eval_ns"].get<double>()) << "," << r["furnace_samples"].get<int>() << "," << fmt(r["furnace_importance"].get<double>(), 6) << ","
        << fmt(r["furnace_importance_stderr"].get<double>()) << "," << fmt(r["furnace_uniform"].get<double>(), 6) << ","
        << fmt(r["furnace_uniform_stderr"].get<double>()) << "," << fmt(r["variance_ratio_uniform_over_importance"].get<double>()) << "\n";
    md << "| " << r["reconstruction"].get<std::string>() << " | " << r["case"].get<std::string>() << " | " << fmt(r["sample_ns"].get<double>()) << " | " << fmt(r["pdf_ns"].get<double>()) << " | "
       << fmt(r["eval_ns"].get<double>()) << " | " << fmt(r["fibre_prepare_us"].get<double>()) << " | " << fmt(r["fibre_sample_ns"].get<double>()) << " | "
       << fmt(r["fibre_pdf_ns"].get<double>()) << " | " << fmt(r["fibre_eval_ns"].get<double>()) << " | " << fmt(r["furnace_importance"].get<double>(), 5) << " ± "
       << fmt(r["furnace_importance_stderr"].get<double>(), 2) << " | " << fmt(r["furnace_uniform"].get<double>(), 5) << " ± "
       << fmt(r["furnace_uniform_stderr"].get<double>(), 2) << " | " << fmt(r["variance_ratio_uniform_over_importance"].get<double>()) << " |\n";
  }
  md << "\nPreparing the sampler of the full default tables (cubic, as baked): " << fmt(prepare_stored_ms) << " ms with the sampling data stored in the file, "
     << fmt(prepare_computed_ms) << " ms computing them (prefix integrals and clamp bounds).\n";
  md << "\n" << furnace_n << " samples per furnace estimate (through the FibreSampler); sample() includes the value and the mixture pdf of the\n"
     << "drawn direction. HairSampler reads the full tables; FibreSampler first blends N_p and M_p over the fibre's beta and sigma_a.\n"
     << "Reconstruction: the N_p and M_p tables' nodes interpolated as baked (cubic; the mixture path from the stored sampling data\n"
     << "where few cells need the clamp, else the general path, one blended row per lookup), linear along every axis, or cubic along\n"
     << "the sampled axes only (both: sampling data computed when the sampler is prepared). Load average at the start: " << s.machine.value("load_average_at_start", std::string("?")) << ".\n";
  write_file(s, "sampling.csv", csv.str());
  write_file(s, "sampling.md", md.str());
  return out;
}

}  // namespace bench
