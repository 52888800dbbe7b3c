// Loads a baked table set and samples one fiber the way a path tracer does: a direction drawn
// in proportion to S, its weight S / pdf, S itself and the pdf for multiple importance sampling.
//
//   load-and-sample [FILE]   (default: tables/default/hairlut-default.h5)
#include <cstdio>
#include <hairlut/io/table_io.hpp>
#include <hairlut/tables/hair_views.hpp>

int main(int argc, char** argv) {
  const hairlut::TableSet set = hairlut::load_tables(argc > 1 ? argv[1] : "tables/default/hairlut-default.h5");
  const auto hair = hairlut::hair_scattering<float>(set);  // once per table set; const, shared by threads

  // RGB absorption from melanin (eumelanin 0.8, pheomelanin 0.2), beta_m and beta_n in radians.
  const hairlut::sampler::Fiber fiber = hairlut::fiber_from_melanin(0.8, 0.2, 0.2, 0.2);

  const double wo[3] = {0.3, 0.9539392014169456, 0.0};  // unit vector towards the viewer, fiber frame
  const double u[3] = {0.5, 0.25, 0.75};                // three uniform numbers in [0, 1)
  const hairlut::sampler::ScatteringSample s = hair.sample(fiber, wo, u);
  double f[3];
  hair.eval(fiber, wo, s.wi, f);                 // S(wo, wi) per channel [1/sr]
  const double pdf = hair.pdf(fiber, wo, s.wi);  // the density sample() drew from (for MIS)
  std::printf("wi (%.3f %.3f %.3f): weight %.4f %.4f %.4f = S / pdf, pdf %.4f = %.4f, S %.4f %.4f %.4f\n", s.wi[0], s.wi[1],
              s.wi[2], s.weight[0], s.weight[1], s.weight[2], s.pdf, pdf, f[0], f[1], f[2]);

  // The same tables prepared for one roughness (a material's beta_m, beta_n): a fraction of a
  // second once, then a few bilinear lookups per call; sigma_a stays per fiber, read through a
  // state built once per strand (a few microseconds).
  const auto material = hairlut::sampler::HairScattering<float>(hair, fiber);
  const hairlut::sampler::PreparedFiber strand = material.fiber(fiber);
  const hairlut::sampler::ScatteringSample m = material.sample(strand, wo, u);
  std::printf("prepared: wi (%.3f %.3f %.3f), weight %.4f %.4f %.4f, pdf %.4f = %.4f\n", m.wi[0], m.wi[1], m.wi[2], m.weight[0],
              m.weight[1], m.weight[2], m.pdf, material.pdf(strand, wo, m.wi));
  return s.pdf > 0.0 && m.pdf > 0.0 ? 0 : 1;
}
