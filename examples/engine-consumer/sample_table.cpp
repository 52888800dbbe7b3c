// Loads a baked hairlut table set and looks up the N_p table of one lobe at physical arguments
// through the typed views (built once from the file's metadata), then S of a fiber from all the
// tables through the renderer runtime (HairScattering), as an engine's asset importer and shading
// code would.
//
//   sample-table FILE LOBE THETA_D_DEG SIGMA_A BETA_DEG PHI_DEG
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/io/table_io.hpp>
#include <hairlut/util/version.hpp>
#include <string>

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: sample-table FILE LOBE THETA_D_DEG SIGMA_A BETA_DEG PHI_DEG\n");
    return 2;
  }
  try {
    const double deg = 3.14159265358979323846 / 180.0;
    const double theta_d = std::atof(argv[3]) * deg, sigma_a = std::atof(argv[4]), beta = std::atof(argv[5]) * deg,
                 phi = std::atof(argv[6]) * deg;
    const hairlut::TableSet set = hairlut::load_tables(argv[1]);
    // Views of every lobe's N_p (with its energy factor) and M_p, from the file's metadata.
    const auto tables = hairlut::hair_tables<float, double>(set);
    const int p = hairlut::lobe_index(set, argv[2]);
    const double value = tables.np[p](beta, sigma_a, theta_d, phi);
    std::printf("hairlut %s: np/%s(theta_d=%s deg, sigma_a=%s, beta=%s deg, phi=%s deg) = %.9g 1/rad\n", hairlut::kVersion, argv[2], argv[3],
                argv[4], argv[5], argv[6], value);
    // S of a fiber with this σa in every channel and β for both roughnesses, at θi = −θd and the
    // held direction θo (the tables' θr) = θd.
    hairlut::sampler::Fiber fiber;
    fiber.sigma_a[0] = fiber.sigma_a[1] = fiber.sigma_a[2] = sigma_a;
    fiber.beta_m = fiber.beta_n = beta;
    const hairlut::sampler::HairScattering<float> runtime = hairlut::hair_scattering<float>(set);
    double rgb[3];
    runtime.eval(fiber, theta_d, -theta_d, phi, rgb);
    std::printf("S(theta_i=%s deg, theta_r=%s deg, phi=%s deg) = %.9g (all lobes and the residual)\n", ("-" + std::string(argv[3])).c_str(),
                argv[3], argv[6], rgb[0]);
    return std::isfinite(value) && std::isfinite(rgb[0]) ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sample-table: error: %s\n", e.what());
    return 1;
  }
}
