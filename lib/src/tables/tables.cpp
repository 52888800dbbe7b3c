#include "hairlut/tables/tables.hpp"

#include <algorithm>
#include <cmath>

// half's conversions inline (bit shifts, the same values as libImath's table): this layer links no
// OpenEXR or Imath library.
#define IMATH_HALF_NO_LOOKUP_TABLE
#include <Imath/half.h>

#include "hairlut/util/error.hpp"
#include "hairlut/util/hash.hpp"

namespace hairlut {

void Table::allocate(Precision p) {
  precision = p;
  const std::size_t n = grid_size(axes);
  f32.clear();
  f64.clear();
  if (p == Precision::float32) f32.assign(n, 0.0f);
  else f64.assign(n, 0.0);
}

double Table::sample(const std::vector<double>& x) const {
  if (x.size() != axes.size())
    throw DomainError("sample point of table " + path() + " must have " + std::to_string(axes.size()) + " coordinates (got " +
                      std::to_string(x.size()) + ")");
  std::vector<sampler::Axis> v;
  for (const GridAxis& a : axes) v.push_back(a.view());
  const int dims = static_cast<int>(v.size());
  const double value = precision == Precision::float32 ? sampler::sample(f32.data(), v.data(), dims, x.data())
                                                       : sampler::sample(f64.data(), v.data(), dims, x.data());
  // Cubic interpolation may undershoot below zero next to a steep fall; a non-negative quantity
  // stays non-negative (shifts are signed, and spectral transmittance is negative out of gamut).
  const double clamped = quantity == "shift" || quantity == "transmittance" ? value : std::max(value, 0.0);
  const sampler::GrazingFactor g = grazing_factor();
  if (g.none()) return clamped;
  double sigma_a = 0.0, theta_d = 0.0;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    if (axes[k].name == "sigma_a") sigma_a = x[k];
    if (axes[k].name == "theta_d") theta_d = x[k];
    // A material's table: σa per channel from its attribute (the node the channel coordinate rounds to).
    if (axes[k].name == "channel") {
      const auto a = attributes.find("sigma_a");
      const double c = std::round(x[k]);
      if (a != attributes.end() && a->is_array() && c >= 0.0 && c < static_cast<double>(a->size()) && (*a)[static_cast<std::size_t>(c)].is_number())
        sigma_a = std::max(0.0, (*a)[static_cast<std::size_t>(c)].get<double>());
    }
  }
  return clamped * g(sigma_a, theta_d);
}

sampler::GrazingFactor Table::grazing_factor() const {
  sampler::GrazingFactor g;
  g.cos_power = attributes.value("cos_theta_d_power", 0);
  if (const auto a = attributes.find("grazing_absorption"); a != attributes.end() && a->is_object())
    g.x_scale = a->value("x_scale", 0.0), g.tau = a->value("tau", 0.0), g.b = a->value("b", 0.0), g.c = a->value("c", 0.0), g.d = a->value("d", 0.0),
    g.e = a->value("e", 0.0), g.f = a->value("f", 0.0);
  return g;
}

void Table::set_grazing_factor(const sampler::GrazingFactor& g) {
  if (g.none()) return;
  attributes["cos_theta_d_power"] = g.cos_power;
  if (g.x_scale != 0.0)
    attributes["grazing_absorption"] = {{"x_scale", g.x_scale}, {"tau", g.tau}, {"b", g.b}, {"c", g.c}, {"d", g.d}, {"e", g.e}, {"f", g.f}};
}

double TableSet::sample_value(const Table& t, const std::vector<double>& x) const {
  const double v = t.sample(x);
  const std::string f = t.factor();
  if (f.empty()) return v;
  const Table* ft = find(f);
  if (!ft) throw DomainError("table " + t.path() + ": its factor table " + f + " is missing");
  std::vector<double> y;
  for (const GridAxis& fa : ft->axes) {
    std::size_t k = 0;
    while (k < t.axes.size() && t.axes[k].name != fa.name) ++k;
    if (k == t.axes.size()) throw DomainError("table " + t.path() + ": its factor table " + f + " has axis " + fa.name + " which it lacks");
    y.push_back(x[k]);
  }
  return v * ft->sample(y);
}

nlohmann::ordered_json Table::describe() const {
  return describe([](const GridAxis& a) { return a.to_json(); });
}

nlohmann::ordered_json Table::describe(const std::function<nlohmann::ordered_json(const GridAxis&)>& axis_json) const {
  nlohmann::ordered_json j;
  j["path"] = path();
  j["group"] = group;
  j["name"] = name;
  j["quantity"] = quantity;
  j["units"] = units;
  j["long_name"] = long_name;
  j["dims"] = nlohmann::ordered_json::array();
  for (const GridAxis& a : axes) j["dims"].push_back(a.name);
  j["shape"] = nlohmann::ordered_json::array();
  for (const GridAxis& a : axes) j["shape"].push_back(a.count);
  j["axes"] = nlohmann::ordered_json::array();
  for (const GridAxis& a : axes) j["axes"].push_back(axis_json(a));
  j["attributes"] = attributes;
  return j;
}

const Table* TableSet::find(const std::string& path) const {
  for (const Table& t : tables)
    if (t.path() == path) return &t;
  return nullptr;
}

std::size_t TableSet::bytes() const {
  std::size_t b = 0;
  for (const Table& t : tables) b += t.f32.size() * sizeof(float) + t.f64.size() * sizeof(double);
  return b;
}

std::string content_checksum(const TableSet& set, ChecksumRounding rounding, HashAlgorithm algorithm) {
  Hasher h(algorithm);
  h.update(set.metadata.dump());
  for (const Table& t : set.tables) {
    h.update(t.describe().dump());
    if (rounding == ChecksumRounding::as_stored && t.precision == Precision::float64) {
      h.update(t.f64.data(), t.f64.size() * sizeof(double));
    } else if (rounding == ChecksumRounding::as_stored || (rounding == ChecksumRounding::float32 && t.precision == Precision::float32)) {
      h.update(t.f32.data(), t.f32.size() * sizeof(float));
    } else {
      std::vector<float> rounded(t.size());  // hashed in one piece: the same hash as value by value
      for (std::size_t i = 0; i < t.size(); ++i) {
        float v = static_cast<float>(t.get(i));
        if (rounding == ChecksumRounding::half) v = static_cast<float>(half(v));
        rounded[i] = v;
      }
      h.update(rounded.data(), rounded.size() * sizeof(float));
    }
  }
  return h.hex();
}

}  // namespace hairlut
