// What a reader relies on beyond the checksum (table_semantics.hpp).
#include "table_semantics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <regex>
#include <string>

#include "hairlut/io/hdf5_io.hpp"  // IoError
#include "hairlut/tables/beta_bands.hpp"
#include "hairlut/tables/fourier_tables.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut::detail {
namespace {

// R, TT, TRT, TRRT, ... and the residual: the lobes a table of N_p, M_p or their energies is of.
bool is_lobe(const std::string& s) {
  static const std::regex lobe("R|T(R)*T|residual");
  return std::regex_match(s, lobe);
}

// The quantity a table's name implies (empty: the name implies none).
std::string implied_quantity(const Table& t) {
  static const std::regex band("(R|T(R)*T|residual)_band[0-9]+");
  if (t.group.rfind("sampling/", 0) == 0) {
    for (const char* what : {"cdf", "mass", "clamp_bound"}) {
      const std::string tail = std::string("_") + what;
      if (t.name.size() > tail.size() && t.name.compare(t.name.size() - tail.size(), tail.size(), tail) == 0)
        return std::string("sampling_") + what;
    }
    return "";
  }
  const bool material = t.group.rfind("materials/", 0) == 0;
  if (t.group == "np" && (is_lobe(t.name) || std::regex_match(t.name, band))) return "N_p";
  if (t.group == "mp" && is_lobe(t.name)) return "M_p";
  if ((t.group == "np" || material) && t.name.rfind("energy_", 0) == 0 && is_lobe(t.name.substr(7))) return "energy";
  if (material && t.name.rfind("np_", 0) == 0 && is_lobe(t.name.substr(3))) return "N_p";
  if (material && t.name.rfind("mp_", 0) == 0 && is_lobe(t.name.substr(3))) return "M_p";
  return "";
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

bool close(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::max(std::abs(a), std::abs(b))); }

// The grazing factor's attributes (format 3.0): a lookup raises cos θd to cos_theta_d_power and
// scales σa by grazing_absorption's numbers, so each is bounded where the baker's lie (power 0, 1
// or 2; η ≤ 10 gives x_scale ≥ 0.01 and τ ≤ 4.1; b … f are constants below 20).
void check_grazing(const Table& t, const std::string& name) {
  const std::string where = name + ": table " + t.path() + ": attribute ";
  if (const auto p = t.attributes.find("cos_theta_d_power"); p != t.attributes.end())
    if (!p->is_number_integer() || p->get<long long>() < 0 || p->get<long long>() > sampler::GrazingFactor::kMaxCosPower)
      throw IoError(where + "cos_theta_d_power must be 0, 1 or 2");
  if (const auto a = t.attributes.find("grazing_absorption"); a != t.attributes.end()) {
    if (!a->is_object()) throw IoError(where + "grazing_absorption must be an object {x_scale, tau, b, c, d[, e, f]}");
    for (const char* k : {"x_scale", "tau", "b", "c", "d", "e", "f"}) {
      const auto v = a->find(k);
      const bool optional = std::string(k) == "e" || std::string(k) == "f";
      const double x = v != a->end() && v->is_number() ? v->get<double>() : optional && v == a->end() ? 0.0 : -1.0;
      if (!(x >= 0.0 && x <= 1e3) || (x == 0.0 && std::string(k) == "x_scale"))
        throw IoError(where + "grazing_absorption." + k + (std::string(k) == "x_scale" ? " must lie in (0, 1e3]" : " must lie in [0, 1e3]"));
    }
  }
}

void check_bands(const TableSet& set, const std::string& name) {
  const auto it = set.metadata.find("np_beta_bands");
  if (it == set.metadata.end()) return;
  const auto fail = [&](const std::string& what) { throw IoError(name + ": metadata np_beta_bands: " + what); };
  const nlohmann::ordered_json& bands = *it;
  if (!bands.is_array() || bands.empty() || bands.size() > 64) fail("must list 1 to 64 bands");
  double previous_hi = 0.0;
  for (std::size_t k = 0; k < bands.size(); ++k) {
    const auto& b = bands[k];
    const std::string at = "band " + std::to_string(k);
    if (!b.is_object() || !b.contains("range") || !b["range"].is_array() || b["range"].size() != 2 || !b["range"][0].is_number() ||
        !b["range"][1].is_number() || !b.contains("suffix") || b["suffix"] != beta_band_suffix(static_cast<int>(k)))
      fail(at + ": malformed (a range [lo, hi] and the suffix \"" + beta_band_suffix(static_cast<int>(k)) + "\")");
    const double lo = b["range"][0].get<double>(), hi = b["range"][1].get<double>();
    if (!(std::isfinite(lo) && std::isfinite(hi) && lo > 0.0 && lo <= hi)) fail(at + ": range must be finite, positive and ordered");
    if (k > 0 && !close(lo, previous_hi)) fail(at + ": must begin where band " + std::to_string(k - 1) + " ends (bands tile the beta range)");
    previous_hi = hi;
  }
  // Each band's tables (np/<lobe><suffix>, with the attribute beta_band; the residual is not
  // banded) cover exactly the band's range on their beta axis and name the band.
  static const std::regex banded("(R|T(R)*T|residual)(_band[0-9]+)?");
  for (const Table& t : set.tables) {
    if (t.group != "np" || !std::regex_match(t.name, banded)) continue;
    const bool suffixed = t.name.find("_band") != std::string::npos;
    if (!t.attributes.contains("beta_band")) {
      if (suffixed) throw IoError(name + ": table " + t.path() + ": a band's table without the attribute beta_band");
      continue;
    }
    const auto& a = t.attributes["beta_band"];
    const int k = a.is_object() && a.contains("index") && a["index"].is_number_integer() && a["index"].get<long long>() >= 0 && a["index"].get<long long>() < 64
                        ? a["index"].get<int>()
                        : -1;
    if (k < 0 || k >= static_cast<int>(bands.size()) || !a.contains("count") || a["count"] != bands.size() ||
        t.name.size() < beta_band_suffix(k).size() ||
        t.name.compare(t.name.size() - beta_band_suffix(k).size(), std::string::npos, beta_band_suffix(k)) != 0 || (k == 0 && suffixed))
      throw IoError(name + ": table " + t.path() + ": attribute beta_band does not name this table's band of " + std::to_string(bands.size()));
    const double lo = bands[static_cast<std::size_t>(k)]["range"][0].get<double>(), hi = bands[static_cast<std::size_t>(k)]["range"][1].get<double>();
    if (t.axes.empty() || t.axes[0].name != "beta" || !close(t.axes[0].lo, lo) || !close(t.axes[0].hi, hi))
      throw IoError(name + ": table " + t.path() + ": its beta axis does not cover band " + std::to_string(k) + "'s range");
  }
}

template <class V>
std::size_t first_bad(const V& values, bool non_negative) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]) || (non_negative && values[i] < 0)) return i;
  return values.size();
}

// A slice's mass is its prefix mass at the last node, doubled for an even axis (the prefix runs
// over [0, pi], the mass over the whole circle): both are stored, and a mass that disagrees (1e300
// in place of 0.4) would weight its lobe by it.
void check_masses(const TableSet& set, const Table& mass, const std::string& name) {
  const std::string base = mass.name.substr(0, mass.name.size() - 5);  // less "_mass"
  const Table* cdf = nullptr;
  for (const Table& t : set.tables)
    if (t.group == mass.group && t.name == base + "_cdf") cdf = &t;
  if (!cdf) throw IoError(name + ": table " + mass.path() + " has no " + mass.group + "/" + base + "_cdf beside it");
  const std::size_t n = cdf->axes.empty() ? 0 : static_cast<std::size_t>(cdf->axes.back().count);
  if (n == 0 || mass.size() * n != cdf->size())
    throw IoError(name + ": table " + mass.path() + " does not hold one mass per slice of " + cdf->path());
  const double factor = cdf->axes.back().wrap == Wrap::even ? 2.0 : 1.0;
  // Both stored as float64 (HDF5): equal but for the last bit. Held as float32 (OpenEXR, where
  // they may be half): each rounded on its own, to 2^-11 relative and half's subnormal spacing
  // 2^-24 (6e-8) absolute.
  const bool exact = mass.precision == Precision::float64 && cdf->precision == Precision::float64;
  for (std::size_t s = 0; s < mass.size(); ++s) {
    const double m = mass.get(s), want = factor * cdf->get(s * n + n - 1);
    const double tolerance = exact ? 1e-12 * std::max(1.0, std::abs(want)) : 4e-3 * std::abs(want) + 2.4e-7;
    if (!(std::abs(m - want) <= tolerance))
      throw IoError(name + ": table " + mass.path() + ": mass " + std::to_string(s) + " is " + num(m) + ", its prefix masses end at " +
                    num(want) + " (sampling data inconsistent)");
  }
}

}  // namespace

void check_table_semantics(const TableSet& set, const std::string& name) {
  for (const Table& t : set.tables) {
    const std::string want = implied_quantity(t);
    if (!want.empty() && t.quantity != want)
      throw IoError(name + ": table " + t.path() + " has quantity \"" + t.quantity.substr(0, 40) + "\"; its name says " + want);
    if (want.empty() && t.quantity.rfind("sampling_", 0) == 0)
      throw IoError(name + ": table " + t.path() + " has quantity \"" + t.quantity.substr(0, 40) + "\" but is not named as sampling data");
    // Sampling data steer every sample a renderer draws: finite, and masses and clamp bounds >= 0
    // (prefix masses may dip where the interpolant does: the clamp bounds cover that).
    if (want.rfind("sampling_", 0) == 0) {
      const bool non_negative = want == "sampling_clamp_bound";
      const std::size_t bad = t.precision == Precision::float32 ? first_bad(t.f32, non_negative) : first_bad(t.f64, non_negative);
      if (bad < t.size())
        throw IoError(name + ": table " + t.path() + ": value " + std::to_string(bad) + " is " + num(t.get(bad)) +
                      (non_negative ? " (sampling data must be finite and >= 0)" : " (sampling data must be finite)"));
    }
    if (want == "sampling_mass") check_masses(set, t, name);
    check_grazing(t, name);
    if (is_fourier_table(t)) {
      try {
        (void)fourier_table_info(t);
      } catch (const DomainError& e) {
        throw IoError(name + ": " + e.what());
      }
    }
  }
  check_bands(set, name);
}

}  // namespace hairlut::detail
