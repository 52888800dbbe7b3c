// bench-hair-luts, section "sampling": the cost of the renderer runtime's (HairScattering) sample(),
// pdf() and eval() per call on the shipped default tables (one thread), per single call and through
// one shading point, and the variance of a white-furnace estimate of ∫ S dω with its importance
// sampling against uniform sampling of θi and φ at the same sample count. Writes sampling.json,
// .csv and .md.
#include <cmath>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "hairlut/io/table_io.hpp"
#include "hairlut/tables/hair_views.hpp"

namespace bench {

namespace {

// The default tables' views as baked (r = 0), linear along every N_p and M_p axis (r = 1), or cubic
// along the axes the runtime samples only, φ of N_p and θi of M_p (r = 2); the energy factors keep
// their own interpolation. The views copy the axes.
hairlut::sampler::HairTables<float, double> reconstruction(const hairlut::TableSet& set, int r) {
  using namespace hairlut::sampler;
  HairTables<float, double> h = hairlut::hair_tables<float, double>(set);
  if (r == 0) return h;
  auto axes_of = [&](const hairlut::Table& t, int sampled, Axis* a) {
    for (std::size_t d = 0; d < t.axes.size(); ++d) {
      a[d] = t.axes[d].view();
      if (a[d].interpolation == Interpolation::cubic && !(r == 2 && static_cast<int>(d) == sampled)) a[d].interpolation = Interpolation::linear;
    }
  };
  const auto& lobes = set.metadata.at("lobes");
  for (int p = 0; p <= h.lobes; ++p) {
    const std::string lobe = p < h.lobes ? lobes[static_cast<std::size_t>(p)].get<std::string>() : std::string("residual");
    const hairlut::Table* np = set.find("np/" + lobe);
    const hairlut::Table* mp = set.find("mp/" + lobe);
    if (!np || !mp) continue;
    const hairlut::Table* e = set.find(np->factor());
    Axis na[4], ma[3], ea[2];
    axes_of(*mp, 1, ma);
    if (e) ea[0] = e->axes[0].view(), ea[1] = e->axes[1].view();
    axes_of(*np, p < h.lobes ? 3 : -1, na);
    if (p < h.lobes) {
      h.np[p] = NpLobe<float, double>(np->f32.data(), na, e ? e->f32.data() : nullptr, e ? ea : nullptr, e ? e->grazing_factor() : GrazingFactor{});
      h.mp[p] = MpLobe<float, double>(mp->f32.data(), ma);
    } else {
      h.np_residual = NpResidual<float, double>(np->f32.data(), na, e ? e->f32.data() : nullptr, e ? ea : nullptr,
                                                np->grazing_factor(), e ? e->grazing_factor() : GrazingFactor{});
      h.mp_residual = MpLobe<float, double>(mp->f32.data(), ma);
    }
  }
  return h;
}

double mean3(const double* rgb) { return (rgb[0] + rgb[1] + rgb[2]) / 3.0; }

}  // namespace

json bench_sampling(const Settings& s) {
  using Runtime = hairlut::sampler::HairScattering<float>;
  constexpr double pi = 3.14159265358979323846, deg = pi / 180.0;
  const std::string file = s.source_dir + "/tables/default/hairlut-default.h5";
  const hairlut::TableSet set = hairlut::load_tables(file);
  // Three reconstructions of the same nodes: as baked (cubic along every N_p and M_p axis: the
  // general path, a blended row per lookup), linear along every axis (the mixture fast path at
  // every lookup) and cubic along the sampled axes φ and θi only (the fast path where a node
  // slice does not dip below 0). The energy tables keep their own interpolation.
  const char* const recon_names[] = {"cubic (as baked)", "linear", "cubic along phi, theta_i only"};
  std::vector<Runtime> recons;
  for (int r = 0; r < 3; ++r) recons.push_back(r == 0 ? hairlut::hair_scattering<float>(set) : Runtime(reconstruction(set, r)));
  // Building the runtime over the full tables: with the N_p tables' sampling data stored in the
  // file (pointers into the loaded tables) against computing them (the prefix integrals and the
  // clamp bounds); both lay the M_p tables out along θi and compute theirs.
  double prepare_stored_ms = 0.0, prepare_computed_ms = 0.0;
  {
    double t0 = thread_cpu_seconds();
    const Runtime stored = hairlut::hair_scattering<float>(set);
    prepare_stored_ms = (thread_cpu_seconds() - t0) * 1e3;
    const hairlut::sampler::HairTables<float, double> views = hairlut::hair_tables<float, double>(set);
    t0 = thread_cpu_seconds();
    const Runtime computed(views);
    prepare_computed_ms = (thread_cpu_seconds() - t0) * 1e3;
    if (!stored.valid() || !computed.valid()) log(s.quiet, "sampling: the default tables cannot be sampled\n");
  }
  struct Case {
    const char* name;
    double beta, sigma_a, theta_o;
  };
  const Case cases[] = {{"narrow, white, theta_o 30 deg", 4.5 * deg, 0.0, 30.0 * deg},
                        {"medium, brown, theta_o 0", 10.0 * deg, 1.5, 0.0},
                        {"wide, white, theta_o -20 deg", 30.0 * deg, 0.0, -20.0 * deg},
                        {"grazing, white, theta_o 85 deg", 10.0 * deg, 0.0, 85.0 * deg}};
  const int calls = s.quick ? 2000 : 20000;
  const int furnace_n = s.quick ? 20000 : 200000;
  json rows = json::array();
  for (int rc = 0; rc < 3; ++rc)
  for (const Case& c : cases) {
    const Runtime& rt = recons[static_cast<std::size_t>(rc)];
    log(s.quiet, "sampling: %s, %s ...\n", recon_names[rc], c.name);
    hairlut::sampler::Fiber f;
    f.beta_m = f.beta_n = c.beta;
    f.sigma_a[0] = f.sigma_a[1] = f.sigma_a[2] = c.sigma_a;
    const double wo[3] = {std::sin(c.theta_o), std::cos(c.theta_o), 0.0};
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<double> us(static_cast<std::size_t>(3 * calls));
    for (double& v : us) v = u(rng);
    // sample(f, wo, u): the shading point at wo built per call, then the direction, its weight and
    // the mixture pdf.
    std::vector<hairlut::sampler::ScatteringSample> drawn(static_cast<std::size_t>(calls));
    double t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) drawn[static_cast<std::size_t>(k)] = rt.sample(f, wo, &us[static_cast<std::size_t>(3 * k)]);
    const double sample_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    double sink = 0.0;
    t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) sink += rt.pdf(f, wo, drawn[static_cast<std::size_t>(k)].wi);
    const double pdf_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) {
      double rgb[3];
      rt.eval(f, wo, drawn[static_cast<std::size_t>(k)].wi, rgb);
      sink += rgb[0];
    }
    const double eval_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    // The same through one ShadingPoint (at(f, wo): each lobe's θi density at this wo, built once).
    t0 = thread_cpu_seconds();
    const Runtime::ShadingPoint sp = rt.at(f, wo);
    const double prepare_us = (thread_cpu_seconds() - t0) * 1e6;
    t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) sink += sp.sample(&us[static_cast<std::size_t>(3 * k)]).pdf;
    const double point_sample_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) sink += sp.pdf(drawn[static_cast<std::size_t>(k)].wi);
    const double point_pdf_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    t0 = thread_cpu_seconds();
    for (int k = 0; k < calls; ++k) {
      double rgb[3];
      sp.eval(drawn[static_cast<std::size_t>(k)].wi, rgb);
      sink += rgb[0];
    }
    const double point_eval_ns = (thread_cpu_seconds() - t0) / calls * 1e9;
    // Furnace ∫ S dω (channels averaged): importance sampling (weight S / pdf) against uniform
    // θi ∈ [−π/2, π/2] and φ ∈ [−π, π] (pdf per solid angle 1 / (2π² cos θi)), the same number of
    // samples.
    double is_sum = 0.0, is_sum2 = 0.0, un_sum = 0.0, un_sum2 = 0.0;
    for (int k = 0; k < furnace_n; ++k) {
      const double v[3] = {u(rng), u(rng), u(rng)};
      const auto r = sp.sample(v);
      const double x = r.pdf > 0.0 ? mean3(r.weight) : 0.0;
      is_sum += x, is_sum2 += x * x;
      const double ti = (u(rng) - 0.5) * pi, phi = (2.0 * u(rng) - 1.0) * pi;
      double rgb[3];
      rt.eval(f, c.theta_o, ti, phi, rgb);
      const double y = mean3(rgb) * std::cos(ti) * 2.0 * pi * pi;
      un_sum += y, un_sum2 += y * y;
    }
    const double n = furnace_n;
    const double is_mean = is_sum / n, un_mean = un_sum / n;
    const double is_var = std::max(0.0, is_sum2 / n - is_mean * is_mean), un_var = std::max(0.0, un_sum2 / n - un_mean * un_mean);
    rows.push_back({{"case", c.name},
                    {"reconstruction", recon_names[rc]},
                    {"beta_deg", c.beta / deg},
                    {"sigma_a", c.sigma_a},
                    {"theta_o_deg", c.theta_o / deg},
                    {"sample_ns", sample_ns},
                    {"pdf_ns", pdf_ns},
                    {"eval_ns", eval_ns},
                    {"point_prepare_us", prepare_us},
                    {"point_sample_ns", point_sample_ns},
                    {"point_pdf_ns", point_pdf_ns},
                    {"point_eval_ns", point_eval_ns},
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
  csv << "reconstruction,case,sample_ns,pdf_ns,eval_ns,point_prepare_us,point_sample_ns,point_pdf_ns,point_eval_ns,furnace_samples,furnace_importance,stderr_importance,furnace_uniform,stderr_uniform,variance_ratio\n";
  md << "# Sampling: cost per call and furnace variance (default tables, one thread)\n\n"
     << "| reconstruction | case | sample() ns | pdf() ns | eval() ns | ShadingPoint: at() µs | sample() ns | pdf() ns | eval() ns | furnace, importance (± 1σ) | furnace, uniform θi, φ (± 1σ) | variance uniform / importance |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const json& r : rows) {
    csv << r["reconstruction"].get<std::string>() << "," << r["case"].get<std::string>() << "," << fmt(r["sample_ns"].get<double>()) << "," << fmt(r["pdf_ns"].get<double>()) << ","
        << fmt(r["eval_ns"].get<double>()) << "," << fmt(r["point_prepare_us"].get<double>()) << "," << fmt(r["point_sample_ns"].get<double>()) << ","
        << fmt(r["point_pdf_ns"].get<double>()) << "," << fmt(r["point_eval_ns"].get<double>()) << "," << r["furnace_samples"].get<int>() << "," << fmt(r["furnace_importance"].get<double>(), 6) << ","
        << fmt(r["furnace_importance_stderr"].get<double>()) << "," << fmt(r["furnace_uniform"].get<double>(), 6) << ","
        << fmt(r["furnace_uniform_stderr"].get<double>()) << "," << fmt(r["variance_ratio_uniform_over_importance"].get<double>()) << "\n";
    md << "| " << r["reconstruction"].get<std::string>() << " | " << r["case"].get<std::string>() << " | " << fmt(r["sample_ns"].get<double>()) << " | " << fmt(r["pdf_ns"].get<double>()) << " | "
       << fmt(r["eval_ns"].get<double>()) << " | " << fmt(r["point_prepare_us"].get<double>()) << " | " << fmt(r["point_sample_ns"].get<double>()) << " | "
       << fmt(r["point_pdf_ns"].get<double>()) << " | " << fmt(r["point_eval_ns"].get<double>()) << " | " << fmt(r["furnace_importance"].get<double>(), 5) << " ± "
       << fmt(r["furnace_importance_stderr"].get<double>(), 2) << " | " << fmt(r["furnace_uniform"].get<double>(), 5) << " ± "
       << fmt(r["furnace_uniform_stderr"].get<double>(), 2) << " | " << fmt(r["variance_ratio_uniform_over_importance"].get<double>()) << " |\n";
  }
  md << "\nBuilding the runtime (HairScattering) over the full default tables (cubic, as baked): " << fmt(prepare_stored_ms)
     << " ms with the N_p sampling data stored in the file, " << fmt(prepare_computed_ms) << " ms computing them (prefix integrals and clamp bounds).\n";
  md << "\nTimed through HairScattering<float> at a held direction wo of inclination theta_o (phi_o = 0), one fiber of one sigma_a and\n"
     << "beta_m = beta_n = beta: the first three columns are the runtime's single calls sample(f, wo, u) and pdf(f, wo, wi), each of\n"
     << "which builds the shading point at wo (every lobe's theta_i density) per call, and eval(f, wo, wi); the ShadingPoint\n"
     << "columns time at(f, wo) once, then its sample(u), pdf(wi) and eval(wi) per call. sample() includes S and the mixture pdf of\n"
     << "the drawn direction. " << furnace_n << " samples per furnace estimate (through the ShadingPoint; weights averaged over the channels).\n"
     << "Reconstruction: the N_p and M_p tables' nodes interpolated as baked (cubic; the mixture path from the stored sampling data\n"
     << "where few cells need the clamp, else the general path, one blended row per lookup), linear along every axis, or cubic along\n"
     << "the sampled axes only (both: sampling data computed when the runtime is built). Load average at the start: " << s.machine.value("load_average_at_start", std::string("?")) << ".\n";
  write_file(s, "sampling.csv", csv.str());
  write_file(s, "sampling.md", md.str());
  return out;
}

}  // namespace bench
