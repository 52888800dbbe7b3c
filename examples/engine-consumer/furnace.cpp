// A path-traced white furnace through hairlut's renderer runtime: a fiber lit by a uniform
// environment of radiance 1, seen from several directions wo. Each path combines the two
// strategies a path tracer has, by the balance heuristic: a direction drawn by the hair
// (HairScattering::sample, weight S / pdf) and one drawn uniformly on the sphere (the
// environment's own sampling, S from eval, the hair's pdf from pdf()). Their estimates, and the
// runtime's albedo(), must agree: the reflected radiance is ∫ S dω.
//
//   furnace FILE [EUMELANIN PHEOMELANIN BETA_M_DEG BETA_N_DEG [PATHS]]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <hairlut/io/table_io.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <random>

int main(int argc, char** argv) {
  if (argc != 2 && argc != 6 && argc != 7) {
    std::fprintf(stderr, "usage: furnace FILE [EUMELANIN PHEOMELANIN BETA_M_DEG BETA_N_DEG [PATHS]]\n");
    return 2;
  }
  try {
    const double pi = 3.14159265358979323846, deg = pi / 180.0;
    const hairlut::TableSet set = hairlut::load_tables(argv[1]);
    const auto hair = hairlut::hair_scattering<float>(set);
    const double ce = argc > 2 ? std::atof(argv[2]) : 0.0, cp = argc > 2 ? std::atof(argv[3]) : 0.0;
    const double bm = (argc > 2 ? std::atof(argv[4]) : 10.0) * deg, bn = (argc > 2 ? std::atof(argv[5]) : 10.0) * deg;
    const long paths = argc > 6 ? std::atol(argv[6]) : 100000;
    const hairlut::sampler::Fiber fiber = hairlut::fiber_from_melanin(ce, cp, bm, bn);
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::printf("theta_o   albedo()    MIS estimate (R G B)             hair sampling only   uniform only\n");
    for (double theta_o : {-80.0, -45.0, 0.0, 30.0, 70.0}) {
      const double wo[3] = {std::sin(theta_o * deg), std::cos(theta_o * deg), 0.0};
      double mis[3] = {0, 0, 0}, by_hair = 0.0, by_sphere = 0.0;
      for (long i = 0; i < paths; ++i) {
        // Strategy 1: the hair's own sample.
        const double u[3] = {uniform(rng), uniform(rng), uniform(rng)};
        const hairlut::sampler::ScatteringSample s = hair.sample(fiber, wo, u);
        const double sphere_pdf = 1.0 / (4.0 * pi);
        if (s.pdf > 0.0) {
          const double w = s.pdf / (s.pdf + sphere_pdf);
          for (int c = 0; c < 3; ++c) mis[c] += w * s.weight[c];
          by_hair += s.weight[1];
        }
        // Strategy 2: a direction uniform on the sphere, as an environment light would draw it.
        const double z = 1.0 - 2.0 * uniform(rng), r = std::sqrt(std::max(0.0, 1.0 - z * z)), a = 2.0 * pi * uniform(rng);
        const double wi[3] = {z, r * std::cos(a), r * std::sin(a)};
        double f[3];
        hair.eval(fiber, wo, wi, f);
        const double p = hair.pdf(fiber, wo, wi), w = sphere_pdf / (p + sphere_pdf);
        for (int c = 0; c < 3; ++c) mis[c] += w * f[c] / sphere_pdf;
        by_sphere += f[1] / sphere_pdf;
      }
      std::printf("%6.1f    %.5f    %.5f %.5f %.5f          %.5f              %.5f\n", theta_o, hair.albedo(fiber, wo), mis[0] / paths,
                  mis[1] / paths, mis[2] / paths, by_hair / paths, by_sphere / paths);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "furnace: error: %s\n", e.what());
    return 1;
  }
}
