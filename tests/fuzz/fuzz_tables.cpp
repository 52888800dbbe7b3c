// libFuzzer target: a small baked table set, altered as the input bytes say and written again by
// write_hdf5 (which recomputes the content checksum, as an attacker would), then loaded
// (read_hdf5_memory) and, when the loader accepts it, read by the runtime: HairScattering over
// the loaded tables evaluates, samples and gives pdfs at points the bytes choose. Valid outcomes
// are an IoError or DomainError (the loader or the views refuse) or finite-or-NaN numbers; a
// crash, a hang or a sanitizer report is a bug.
//
// Input: records of 16 bytes: [0] what to alter, [1..3] which table, value or attribute,
// [4..11] a double (raw bits), [12..15] unused; then the sampler's query points from the rest.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/io/hdf5_io.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/util/error.hpp>
#include <iterator>
#include <string>
#include <vector>

namespace {

// The seed set: baked once per process (a second).
const hairlut::TableSet& seed() {
  static const hairlut::TableSet set = [] {
    const auto doc = nlohmann::json::parse(R"({
      "name": "fuzz-tables", "lobes": { "explicit": ["R", "TT", "TRT"], "residual": true }, "quadrature": { "order": 32 },
      "tables": {
        "np": { "axes": { "theta_d": { "count": 3, "range_deg": [0, 60] }, "phi": { "count": 5 },
                          "sigma_a": { "count": 2, "range": [0, 1] }, "beta": { "count": 2, "range_deg": [8, 20] } } },
        "mp": { "axes": { "theta_i": { "count": 3, "range_deg": [-60, 60] }, "theta_r": { "count": 5, "range_deg": [-90, 90] },
                          "beta": { "count": 2, "range_deg": [5, 15] } } } },
      "output": { "basename": "fuzz", "formats": ["hdf5"] } })");
    return hairlut::bake(hairlut::parse_config(doc, "fuzz-tables.json", "."), {});
  }();
  return set;
}

double number(const std::uint8_t* p) {
  double v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// A number in [0, 1) from 8 bytes.
double unit(const std::uint8_t* p) {
  std::uint64_t v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<double>(v >> 11) * 0x1.0p-53;
}

void alter(hairlut::TableSet& set, const std::uint8_t* r) {
  if (set.tables.empty()) return;
  hairlut::Table& t = set.tables[r[1] % set.tables.size()];
  const double v = number(r + 4);
  switch (r[0] % 8) {
    case 0:
    case 1:
    case 2:  // a value
      if (t.size() > 0) t.set((static_cast<std::size_t>(r[2]) << 8 | r[3]) % t.size(), v);
      break;
    case 3: {  // a numeric attribute
      std::vector<std::string> keys;
      for (const auto& [key, value] : t.attributes.items())
        if (value.is_number()) keys.push_back(key);
      if (!keys.empty()) t.attributes[keys[r[2] % keys.size()]] = v;
      break;
    }
    case 4: {  // an axis's range end (values stay: the axis describes other nodes)
      if (t.axes.empty()) break;
      hairlut::GridAxis& a = t.axes[r[2] % t.axes.size()];
      (r[3] & 1 ? a.hi : a.lo) = v;
      break;
    }
    case 5: {  // the quantity of one table set to another's
      t.quantity = set.tables[r[2] % set.tables.size()].quantity;
      break;
    }
    case 6:  // the table dropped
      set.tables.erase(set.tables.begin() + static_cast<std::ptrdiff_t>(r[1] % set.tables.size()));
      break;
    default: {  // a numeric metadata entry
      std::vector<std::string> keys;
      for (const auto& [key, value] : set.metadata.items())
        if (value.is_number()) keys.push_back(key);
      if (!keys.empty()) set.metadata[keys[r[2] % keys.size()]] = v;
      break;
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hairlut::TableSet set = seed();
  std::size_t at = 0;
  for (int n = 0; n < 4 && at + 16 <= size; ++n, at += 16) alter(set, data + at);
  const std::filesystem::path file = std::filesystem::temp_directory_path() / ("fuzz-tables-" + std::to_string(::getpid()) + ".h5");
  try {
    hairlut::write_hdf5(set, file);
  } catch (const std::exception&) {
    return 0;  // the writer refuses what it cannot store (a non-finite attribute, a grid that does not match)
  }
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    const hairlut::TableSet loaded = hairlut::read_hdf5_memory(bytes.data(), bytes.size(), "fuzz.h5");
    const hairlut::sampler::HairScattering<float> rt = hairlut::hair_scattering<float>(loaded);
    double sink = 0.0;
    // Query points a renderer could ask for (the file is the hostile part, not the query).
    constexpr double kPi = 3.14159265358979323846;
    for (; at + 40 <= size; at += 40) {
      hairlut::sampler::Fiber f;
      f.beta_m = f.beta_n = 0.01 + 0.5 * unit(data + at);
      f.sigma_a[0] = f.sigma_a[1] = f.sigma_a[2] = 2.0 * unit(data + at + 8);
      const double theta_o = (unit(data + at + 16) - 0.5) * kPi, theta_i = (unit(data + at + 24) - 0.5) * kPi;
      const double phi = (2.0 * unit(data + at + 32) - 1.0) * kPi;
      double rgb[3];
      rt.eval(f, theta_o, theta_i, phi, rgb);
      sink += rgb[0];
      const double wo[3] = {std::sin(theta_o), std::cos(theta_o), 0.0};
      const hairlut::sampler::HairScattering<float>::ShadingPoint sp = rt.at(f, wo);
      sink += sp.pdf(theta_i, phi);
      const double u[3] = {unit(data + at + 24), unit(data + at + 32), unit(data + at)};
      sink += sp.sample(u).pdf;
    }
    (void)sink;
  } catch (const hairlut::IoError& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) __builtin_trap();
  } catch (const hairlut::DomainError&) {
  }
  return 0;
}
