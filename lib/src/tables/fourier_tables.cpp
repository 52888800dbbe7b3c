#include "hairlut/tables/fourier_tables.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

using json = nlohmann::ordered_json;

const char* kSeries =
    "N_p(phi; beta, sigma_a, theta_d) = F / (2 pi) [c_0 + 2 sum_{n=1}^{N(beta)} exp(-n^2 beta^2 / 2) c_n cos(n phi)], c_n this table "
    "interpolated at (theta_d, sigma_a); beta below beta_min reads beta_min, every larger beta is exact; the result clamped at 0";
const char* kTruncation =
    "N(beta) = the smallest N with 2 exp(-(N+1)^2 b) / (1 - exp(-(2N+3) b)) <= tolerance / 2, b = beta^2 / 2, at most terms - 1 "
    "(a bound on 2 sum_{n>N} exp(-n^2 b): the truncation is below tolerance x c_0 F / 2 pi); summing more stored terms only adds accuracy";
const char* kChord =
    "F = exp(-p sigma_a' l_min), the lobe's least absorption (its shortest internal segment, at the fiber's edge h = +-1): sigma_a' = "
    "sigma_a eta / q, q^2 = eta^2 - sin^2 theta_d, l_min = 2 cos gamma_t = 2 sqrt(eta^2 - 1) / q (chord), so F = exp(-2 p eta "
    "sqrt(eta^2 - 1) sigma_a / q^2)";
const char* kPapers =
    "F = exp(-p sigma_a' l_min), the lobe's least absorption (its shortest internal segment, at the fiber's edge h = +-1): sigma_a' = "
    "sigma_a eta / q, q^2 = eta^2 - sin^2 theta_d, l_min = 4 cos^2 gamma_t = 4 (eta^2 - 1) / q^2 (papers), so F = exp(-4 p eta "
    "(eta^2 - 1) sigma_a / q^3)";
const char* kInterpolation =
    "theta_d and sigma_a as their axes declare (linear or Catmull-Rom in the mapped coordinate, with the axes' end rules); n is "
    "not interpolated";

double number(const Table& t, const char* key) {
  const auto it = t.attributes.find(key);
  if (it == t.attributes.end() || !it->is_number()) throw DomainError("table " + t.path() + ": attribute " + key + " missing or not a number");
  return it->get<double>();
}

}  // namespace

bool is_fourier_table(const Table& t) { return t.group == kFourierGroup && t.quantity == kFourierQuantity; }

bool has_fourier_np(const TableSet& set) { return std::any_of(set.tables.begin(), set.tables.end(), is_fourier_table); }

GridAxis fourier_n_axis(int terms) {
  GridAxis a;
  a.name = "n";
  a.units = "1";
  a.long_name = "order n of the cosine series term cos(n phi) (not interpolated)";
  a.spacing = Spacing::explicit_values;
  a.count = terms;
  for (int n = 0; n < terms; ++n) a.values.push_back(n);
  a.lo = 0.0, a.hi = terms - 1.0;
  return a;
}

json fourier_attributes(const FourierTableInfo& i, const std::string& absorption_path) {
  const sampler::FourierNpParams& f = i.params;
  json a = {{"lobe", i.lobe}};
  if (i.lobe == "residual") a["p_from"] = i.p, a["uniform_in"] = json::array({"phi", "beta"});
  else a["p"] = i.p;
  a["representation"] = "fourier";
  a["series"] = kSeries;
  a["terms"] = f.terms;
  a["beta_min"] = f.beta_min;
  a["beta_max"] = i.beta_max;
  a["tolerance"] = f.tolerance;
  a["truncation"] = kTruncation;
  a["absorption_factor"] = absorption_path == "papers" ? kPapers : kChord;
  a["absorption_p"] = f.absorption_p;
  a["eta"] = f.eta;
  a["absorption_path"] = absorption_path;
  a["interpolation"] = kInterpolation;
  return a;
}

FourierTableInfo fourier_table_info(const Table& t) {
  if (!is_fourier_table(t)) throw DomainError("table " + t.path() + ": not a Fourier N_p table (group np_fourier, quantity fourier_coefficient)");
  if (t.axes.size() != 3 || t.axes[0].name != "theta_d" || t.axes[1].name != "sigma_a" || t.axes[2].name != "n")
    throw DomainError("table " + t.path() + ": a Fourier table's axes must be (theta_d, sigma_a, n)");
  FourierTableInfo i;
  sampler::FourierNpParams& f = i.params;
  i.lobe = t.attributes.value("lobe", std::string());
  if (i.lobe.empty()) throw DomainError("table " + t.path() + ": attribute lobe missing");
  f.terms = static_cast<int>(number(t, "terms"));
  f.beta_min = number(t, "beta_min");
  i.beta_max = number(t, "beta_max");
  f.tolerance = number(t, "tolerance");
  f.eta = number(t, "eta");
  f.absorption_p = static_cast<int>(number(t, "absorption_p"));
  i.p = static_cast<int>(number(t, i.lobe == "residual" ? "p_from" : "p"));
  const std::string path = t.attributes.value("absorption_path", std::string());
  if (path != "chord" && path != "papers") throw DomainError("table " + t.path() + ": attribute absorption_path must be chord or papers");
  f.papers_path = path == "papers";
  f.grazing = t.grazing_factor();
  const std::string where = "table " + t.path() + ": attribute ";
  if (f.terms < 1 || f.terms != t.axes[2].count) throw DomainError(where + "terms must equal the n axis's count");
  // The ranges a config can give (tables.np.axes.beta in [1e-6, pi] rad, fourier.tolerance in
  // (0, 0.1], fiber.eta in (1, 10]): the sampler's series length and bins are sized from them, and
  // a file's values beyond them (beta_min 1e-15, eta 1e300) crashed its readers.
  if (!(f.beta_min >= 1e-6 && f.beta_min <= kPi)) throw_domain_error(where + "beta_min", "must lie in [1e-6, pi] rad", f.beta_min);
  if (!(i.beta_max >= f.beta_min && i.beta_max <= kPi)) throw_domain_error(where + "beta_max", "must lie in [beta_min, pi] rad", i.beta_max);
  if (!(f.tolerance > 0.0 && f.tolerance <= 0.1)) throw_domain_error(where + "tolerance", "must lie in (0, 0.1]", f.tolerance);
  if (!(f.eta > 1.0 && f.eta <= 10.0)) throw_domain_error(where + "eta", "must lie in (1, 10]", f.eta);
  if (f.absorption_p < 0 || f.absorption_p > 64) throw_domain_error(where + "absorption_p", "must lie in [0, 64]", static_cast<long long>(f.absorption_p));
  const GridAxis &th = t.axes[0], &sg = t.axes[1];
  if (th.spacing != Spacing::uniform && th.spacing != Spacing::cos)
    throw DomainError("table " + t.path() + ": axis theta_d must be spaced uniform or cos");
  if (sg.spacing != Spacing::uniform && sg.spacing != Spacing::sqrt)
    throw DomainError("table " + t.path() + ": axis sigma_a must be spaced uniform or sqrt");
  if (th.lo < 0.0 || th.hi > kHalfPi + 1e-12 || sg.lo < 0.0) throw DomainError("table " + t.path() + ": axes beyond theta_d in [0, pi/2], sigma_a >= 0");
  return i;
}

std::vector<GridAxis> fourier_domain(const Table& t) {
  const FourierTableInfo i = fourier_table_info(t);
  GridAxis beta;
  beta.name = "beta", beta.units = "rad", beta.long_name = "azimuthal roughness beta (detector width)";
  beta.spacing = i.beta_max > i.params.beta_min ? Spacing::log : Spacing::uniform;
  beta.lo = i.params.beta_min, beta.hi = i.beta_max, beta.count = i.beta_max > i.params.beta_min ? 8 : 1;
  GridAxis sigma = t.axes[1], theta = t.axes[0];
  GridAxis phi;
  phi.name = "phi", phi.units = "rad", phi.long_name = "relative azimuth phi = phi_r - phi_i";
  phi.wrap = Wrap::even, phi.lo = 0.0, phi.hi = kPi, phi.count = 13;
  if (i.lobe == "residual") return {sigma, theta};
  return {beta, sigma, theta, phi};
}

Table fourier_domain_table(const Table& t) {
  Table d;
  d.group = t.group, d.name = t.name, d.quantity = "N_p", d.units = "1/rad", d.long_name = "N_p of " + t.path();
  d.axes = fourier_domain(t);
  const FourierTableInfo i = fourier_table_info(t);
  d.attributes = {{"lobe", i.lobe}};
  if (i.lobe == "residual") d.attributes["p_from"] = i.p;
  else d.attributes["p"] = i.p;
  return d;
}

std::function<double(const std::vector<double>&)> fourier_point_function(const Table& t) {
  const FourierTableInfo i = fourier_table_info(t);
  const sampler::Axis theta = t.axes[0].view(), sigma = t.axes[1].view();
  const bool residual = i.lobe == "residual";
  if (t.precision == Precision::float32) {
    const auto view = std::make_shared<const sampler::FourierNp<float, double>>(t.f32.data(), theta, sigma, i.params);
    if (residual) return [view](const std::vector<double>& x) { return (*view)(1.0, x[0], x[1], 0.0); };
    return [view](const std::vector<double>& x) { return (*view)(x[0], x[1], x[2], x[3]); };
  }
  const auto view = std::make_shared<const sampler::FourierNp<double, double>>(t.f64.data(), theta, sigma, i.params);
  if (residual) return [view](const std::vector<double>& x) { return (*view)(1.0, x[0], x[1], 0.0); };
  return [view](const std::vector<double>& x) { return (*view)(x[0], x[1], x[2], x[3]); };
}

FourierNpReference::FourierNpReference(const Table& t)
    : table_(&t), info_(fourier_table_info(t)), theta_(t.axes[0].view()), sigma_(t.axes[1].view()) {}

int FourierNpReference::series_terms(double beta) const {
  const double b = std::max(beta, info_.params.beta_min);
  int n = 0;
  while (n < info_.params.terms - 1 && !sampler::fourier_tail_within(n, b, info_.params.tolerance)) ++n;
  return n;
}

void FourierNpReference::coefficients(double sigma_a, double theta_d, int count, std::vector<double>& c, double& F) const {
  const GridAxis &th = table_->axes[0], &sg = table_->axes[1];
  // N_p depends on θd through cos θd: even and 2π-periodic (as the sampler folds it), then clamped.
  const double folded = std::abs(theta_d) <= kPi ? std::abs(theta_d) : std::abs(std::remainder(theta_d, kTwoPi));
  const double theta = std::clamp(folded, th.lo, th.hi), sigma = std::clamp(sigma_a, sg.lo, sg.hi);
  const sampler::Taps a = sampler::taps(theta_, theta), b = sampler::taps(sigma_, sigma);
  const auto terms = static_cast<std::size_t>(info_.params.terms), ns = static_cast<std::size_t>(sg.count);
  c.assign(static_cast<std::size_t>(count), 0.0);
  for (int i = 0; i < a.n; ++i)
    for (int j = 0; j < b.n; ++j) {
      const std::size_t row = (static_cast<std::size_t>(a.i[i]) * ns + static_cast<std::size_t>(b.i[j])) * terms;
      for (std::size_t n = 0; n < c.size(); ++n) c[n] += a.w[i] * b.w[j] * table_->get(row + n);
    }
  F = sampler::fourier_absorption<double>(info_.params, sigma, std::cos(theta)) * info_.params.grazing(sigma, theta);
}

double FourierNpReference::operator()(double beta, double sigma_a, double theta_d, double phi) const {
  if (std::isnan(beta) || std::isnan(sigma_a) || std::isnan(theta_d) || std::isnan(phi)) return std::numeric_limits<double>::quiet_NaN();
  const double b = std::max(beta, info_.params.beta_min);
  const int N = series_terms(b);
  std::vector<double> c;
  double F = 0.0;
  coefficients(sigma_a, theta_d, N + 1, c, F);
  double sum = c[0];
  for (int n = 1; n <= N; ++n) sum += 2.0 * std::exp(-0.5 * n * n * b * b) * c[static_cast<std::size_t>(n)] * std::cos(n * phi);
  return std::max(0.0, sum * F / kTwoPi);
}

double FourierNpReference::energy(double sigma_a, double theta_d) const {
  std::vector<double> c;
  double F = 0.0;
  coefficients(sigma_a, theta_d, 1, c, F);
  return std::max(0.0, c[0] * F);
}

}  // namespace hairlut
