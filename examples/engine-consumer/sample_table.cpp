// Loads a baked hairlut table set and samples the N_p table of one lobe at physical arguments,
// mapping them to the table's axes by name, as an engine's asset importer would.
//
//   sample-table FILE LOBE THETA_D_DEG SIGMA_A BETA_DEG PHI_DEG
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <hairlut/sampler.hpp>
#include <hairlut/table_io.hpp>
#include <hairlut/tables.hpp>
#include <hairlut/version.hpp>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: sample-table FILE LOBE THETA_D_DEG SIGMA_A BETA_DEG PHI_DEG\n");
    return 2;
  }
  try {
    const double deg = 3.14159265358979323846 / 180.0;
    const hairlut::TableSet set = hairlut::load_tables(argv[1]);
    const std::string path = std::string("np/") + argv[2];
    const hairlut::Table* table = set.find(path);
    if (!table) {
      std::fprintf(stderr, "sample-table: error: %s has no table %s\n", argv[1], path.c_str());
      return 1;
    }
    // Physical arguments by axis name: the engine does not need to know the axis order.
    const double theta_d = std::atof(argv[3]) * deg, sigma_a = std::atof(argv[4]), beta = std::atof(argv[5]) * deg,
                 phi = std::atof(argv[6]) * deg;
    std::vector<hairlut::sampler::Axis> axes;
    std::vector<double> x;
    for (const auto& axis : table->axes) {
      axes.push_back(axis.view());
      if (axis.name == "theta_d") x.push_back(theta_d);
      else if (axis.name == "sigma_a") x.push_back(sigma_a);
      else if (axis.name == "beta") x.push_back(beta);
      else if (axis.name == "phi") x.push_back(phi);
      else {
        std::fprintf(stderr, "sample-table: error: %s: unexpected axis %s\n", path.c_str(), axis.name.c_str());
        return 1;
      }
    }
    const int dims = static_cast<int>(axes.size());
    const double value = table->precision == hairlut::Precision::float32
                             ? hairlut::sampler::sample(table->f32.data(), axes.data(), dims, x.data())
                             : hairlut::sampler::sample(table->f64.data(), axes.data(), dims, x.data());
    std::printf("hairlut %s: %s(theta_d=%s deg, sigma_a=%s, beta=%s deg, phi=%s deg) = %.9g %s\n", hairlut::kVersion, path.c_str(),
                argv[3], argv[4], argv[5], argv[6], value, table->units.c_str());
    return std::isfinite(value) ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sample-table: error: %s\n", e.what());
    return 1;
  }
}
