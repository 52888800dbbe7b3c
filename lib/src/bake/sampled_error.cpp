#include "hairlut/bake/sampled_error.hpp"

// half's conversions inline (bit shifts, the same values as libImath's table): this layer links no
// OpenEXR or Imath library.
#define IMATH_HALF_NO_LOOKUP_TABLE
#include <Imath/half.h>
#include <omp.h>

#include <algorithm>
#include <cmath>

#include "hairlut/util/error.hpp"
#include "sampled_error_detail.hpp"

namespace hairlut {
namespace detail::sampled {
namespace {
constexpr int kPeakGrid = 129;
constexpr int kGoldenSteps = 28;
}  // namespace

double domain_hi(const GridAxis& a) {
  constexpr double kHalfPi = 1.5707963267948966, kNear = 2.0 * 3.14159265358979323846 / 180.0;
  return a.name == "theta_d" && a.units == "rad" && a.hi < kHalfPi && a.hi >= kHalfPi - kNear ? kHalfPi : a.hi;
}

bool on_nodes(const GridAxis& a) { return a.name == "channel" || (a.spacing == Spacing::explicit_values && !a.labels.empty()) || a.count < 2; }

double draw(const GridAxis& a, Random& r) {
  const double u = r.uniform();
  if (a.count < 2) return a.nodes().front();
  if (on_nodes(a)) {
    const auto n = a.nodes();
    return n[std::min(n.size() - 1, static_cast<std::size_t>(u * static_cast<double>(n.size())))];
  }
  if (a.spacing == Spacing::explicit_values) return a.values.front() + u * (a.values.back() - a.values.front());
  if (a.spacing == Spacing::log) return std::exp(std::log(a.lo) + u * (std::log(a.hi) - std::log(a.lo)));
  return a.lo + u * (domain_hi(a) - a.lo);
}

double peak_along(const PointFunction& f, std::vector<double> x, int k, double lo, double hi) {
  const auto kk = static_cast<std::size_t>(k);
  auto g = [&](double v) {
    x[kk] = v;
    return std::abs(f(x));
  };
  double best = -1.0;
  int at = 0;
  const double h = (hi - lo) / (kPeakGrid - 1);
  for (int i = 0; i < kPeakGrid; ++i) {
    const double v = g(lo + i * h);
    if (v > best) best = v, at = i;
  }
  double a = lo + std::max(at - 1, 0) * h, b = lo + std::min(at + 1, kPeakGrid - 1) * h;
  const double r = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - r * (b - a), d = a + r * (b - a);
  double fc = g(c), fd = g(d);
  for (int i = 0; i < kGoldenSteps; ++i) {
    if (fc > fd) {
      b = d, d = c, fd = fc;
      c = b - r * (b - a), fc = g(c);
    } else {
      a = c, c = d, fc = fd;
      d = a + r * (b - a), fd = g(d);
    }
    best = std::max(best, std::max(fc, fd));
  }
  return best;
}

}  // namespace detail::sampled

namespace {
using namespace detail::sampled;

Table rounded_to_half(const Table& t) {
  Table h = t;
  for (std::size_t i = 0; i < h.size(); ++i) h.set(i, static_cast<float>(Imath::half(static_cast<float>(t.get(i)))));
  return h;
}

SampledErrorStats stats_of(const std::vector<Sample>& s, bool half) {
  SampledErrorStats st;
  st.points = s.size();
  if (s.empty()) return st;
  std::vector<double> v;
  v.reserve(s.size());
  double sum = 0.0;
  for (const Sample& p : s) {
    const double e = half ? p.rel_half : p.rel;
    v.push_back(e);
    sum += e;
    st.worst = std::max(st.worst, e);
    st.worst_abs = std::max(st.worst_abs, e * p.denominator);
  }
  st.mean = sum / static_cast<double>(v.size());
  const std::size_t rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(v.size()))) - 1;  // nearest rank
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(rank), v.end());
  st.p99 = v[rank];
  return st;
}

}  // namespace

int cell_of(const GridAxis& a, double x) {
  if (a.count < 2) return 0;
  const sampler::Lerp l = sampler::locate(a.view(), x);
  int c = std::min(l.i0, l.i1);
  if (std::abs(l.i0 - l.i1) > 1) c = std::max(l.i0, l.i1);  // wrapped across the period's end
  return std::clamp(c, 0, a.count - 2);
}

namespace {
using namespace detail::sampled;

// The measure of `sampled` (and `half`, when set) over the axes of t (its path names it).
SampledError measure(const Table& t, const PointFunction& sampled, const PointFunction& half, const TableTruth& truth, const SampledErrorOptions& opt) {
  const std::size_t dims = t.axes.size();
  std::vector<int> line_axes;
  std::vector<bool> is_slab(dims, false);
  for (int k : truth.slab_axes) is_slab[static_cast<std::size_t>(k)] = true;
  for (int k = 0; k < static_cast<int>(dims); ++k)
    if (!is_slab[static_cast<std::size_t>(k)] && k != truth.peak_axis) line_axes.push_back(k);
  const bool half_t = static_cast<bool>(half);
  const std::size_t slabs = std::max<std::size_t>(1, (opt.points + kPointsPerSlab - 1) / kPointsPerSlab);
  std::vector<std::vector<Sample>> parts(slabs);
  const bool white = truth.white_floor > 0.0 && static_cast<bool>(truth.make_white);
  const int threads = opt.threads > 0 ? opt.threads : omp_get_max_threads();
  std::atomic<bool> stop{false};
  std::atomic<bool> failed{false};
  std::string failure;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (std::size_t s = 0; s < slabs; ++s) {
    if (stop.load() || (opt.cancel && opt.cancel->load())) {
      stop = true;
      continue;
    }
    try {
      Random rng{mix(opt.seed * 0x9e3779b97f4a7c15ULL + s + 1)};
      std::vector<double> x(dims, 0.0);
      for (std::size_t k = 0; k < dims; ++k) x[k] = t.axes[k].nodes().front();
      for (int k : truth.slab_axes) x[static_cast<std::size_t>(k)] = draw(t.axes[static_cast<std::size_t>(k)], rng);
      const PointFunction f = truth.make(x);
      const PointFunction fw = white ? truth.make_white(x) : PointFunction();
      // The peak search's function: the cheaper evaluation when the truth has one.
      const PointFunction pf = truth.peak_axis >= 0 && truth.make_fast ? truth.make_fast(x, false) : f;
      const PointFunction pfw = truth.peak_axis >= 0 && truth.make_fast && white ? truth.make_fast(x, true) : fw;
      auto add = [&](double denominator) {
        Sample p;
        p.x = x;
        p.exact = f(x);
        p.sampled = sampled(x);
        p.denominator = denominator;
        if (truth.peak_axis < 0) {
          p.denominator = std::max(std::abs(p.exact), truth.absolute_floor);
          if (white) p.denominator = std::max(p.denominator, truth.white_floor * std::abs(fw(x)));
        }
        p.rel = std::abs(p.sampled - p.exact) / p.denominator;
        p.rel_half = half_t ? std::abs(half(x) - p.exact) / p.denominator : 0.0;
        parts[s].push_back(std::move(p));
      };
      if (truth.peak_axis >= 0) {
        const auto pk = static_cast<std::size_t>(truth.peak_axis);
        for (std::size_t l = 0; l < kLinesPerSlab; ++l) {
          for (int k : line_axes) x[static_cast<std::size_t>(k)] = draw(t.axes[static_cast<std::size_t>(k)], rng);
          double den = std::max(peak_along(pf, x, truth.peak_axis, truth.peak_lo, truth.peak_hi), truth.absolute_floor);
          if (white) den = std::max(den, truth.white_floor * peak_along(pfw, x, truth.peak_axis, truth.peak_lo, truth.peak_hi));
          for (std::size_t j = 0; j < kPointsPerLine; ++j) {
            x[pk] = draw(t.axes[pk], rng);
            add(den);
          }
        }
      } else {
        for (std::size_t j = 0; j < kPointsPerSlab; ++j) {
          for (int k : line_axes) x[static_cast<std::size_t>(k)] = draw(t.axes[static_cast<std::size_t>(k)], rng);
          add(0.0);
        }
      }
    } catch (const std::exception& e) {
      if (!failed.exchange(true)) {
#pragma omp critical(hairlut_sampled_error)
        failure = e.what();
      }
      stop = true;
    }
  }
  if (failed) throw DomainError(t.path() + ": " + failure);
  std::vector<Sample> all;
  for (auto& p : parts) std::move(p.begin(), p.end(), std::back_inserter(all));
  SampledError r;
  r.path = t.path();
  r.denominator = truth.denominator;
  r.error = stats_of(all, false);
  if (half_t) r.half = stats_of(all, true);
  r.stages.push_back(stage_of("random", all));
  if (opt.search && !(opt.cancel && opt.cancel->load())) {
    const auto more = worst_point_search(t, sampled, truth, opt, threads, all);
    r.stages.insert(r.stages.end(), more.begin(), more.end());
  }
  r.per_axis_cells.resize(dims);
  for (std::size_t k = 0; k < dims; ++k) r.per_axis_cells[k].assign(on_nodes(t.axes[k]) ? 1 : static_cast<std::size_t>(t.axes[k].count - 1), 0.0);
  double worst = -1.0;
  for (const Sample& p : all) {
    if (p.rel > worst) {
      worst = p.rel, r.found = p.rel;
      r.worst_at = p.x, r.worst_sampled = p.sampled, r.worst_exact = p.exact, r.worst_denominator = p.denominator;
    }
    for (std::size_t k = 0; k < dims; ++k) {
      double& c = r.per_axis_cells[k][on_nodes(t.axes[k]) ? 0 : static_cast<std::size_t>(cell_of(t.axes[k], p.x[k]))];
      c = std::max(c, p.rel);
    }
    if (opt.keep_points) r.x.push_back(p.x), r.rel.push_back(p.rel);
  }
  return r;
}

}  // namespace

SampledError measure_sampled_error(const TableSet& set, const Table& t, const TableTruth& truth, const SampledErrorOptions& opt) {
  // The half-float copy of the table and of its factor table.
  TableSet half_set;
  PointFunction half;
  if (opt.half_float) {
    half_set.tables.push_back(rounded_to_half(t));
    if (const Table* f = set.find(t.factor()); f && !t.factor().empty()) half_set.tables.push_back(rounded_to_half(*f));
    half = [&half_set](const std::vector<double>& x) { return half_set.sample_value(half_set.tables.front(), x); };
  }
  return measure(t, [&](const std::vector<double>& x) { return set.sample_value(t, x); }, half, truth, opt);
}

SampledError measure_sampled_error(const Table& domain, const PointFunction& sampled, const TableTruth& truth, const SampledErrorOptions& options) {
  return measure(domain, sampled, PointFunction(), truth, options);
}

std::uint64_t sampled_error_seed(const std::string& table_path) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : table_path) h = (h ^ c) * 1099511628211ULL;
  return h;
}

}  // namespace hairlut
