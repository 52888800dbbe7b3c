// Sampling data next to the N_p and M_p tables of a set (docs/table-format.md, "Sampling data"):
// computed with the header-only sampler's own AxisSampler::build_data, so that what a file stores
// is what the sampler would compute from the stored values.
#include "hairlut/tables/table_sampling.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <utility>

namespace hairlut {
namespace {


std::size_t grid_values(const std::vector<GridAxis>& axes) {
  std::size_t n = 1;
  for (const GridAxis& a : axes) n *= static_cast<std::size_t>(a.count);
  return n;
}

// Runs the sampler's blocks (sampler::SerialBlocks' form) on `threads` OpenMP threads (0: all),
// dynamically scheduled; each block writes its own entries, so the result does not depend on the
// thread count. The first exception of a block is rethrown after the loop.
struct OmpBlocks {
  int threads = 0;
  template <class Body>
  void operator()(std::size_t n, Body&& body) const {
    std::exception_ptr error;
    std::mutex error_mutex;
    const int t = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(t)
    for (std::size_t i = 0; i < n; ++i) {
      if (error) continue;
      try {
        body(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
    if (error) std::rethrow_exception(error);
  }
};

// The sampler's data of table t (its values as the sampler reads them, float32 or float64, with
// their axis views), computed as AxisSampler computes them, the clamp bounds on `threads` threads.
template <class T>
void build_from(const Table& t, const T* data, sampler::Measure m, std::vector<double>& cdf, std::vector<double>& mass, std::vector<float>& bound,
                int threads) {
  std::vector<sampler::Axis> views;
  for (const GridAxis& g : t.axes) views.push_back(g.view());
  sampler::AxisSampler<T> s(data, views.data(), static_cast<int>(views.size()), m, sampler::AxisData(), OmpBlocks{threads});
  std::move(s).release_data(cdf, mass, bound);
}
void build(const Table& t, sampler::Measure m, std::vector<double>& cdf, std::vector<double>& mass, std::vector<float>& bound, int threads) {
  if (t.precision == Precision::float32) build_from(t, t.f32.data(), m, cdf, mass, bound, threads);
  else build_from(t, t.f64.data(), m, cdf, mass, bound, threads);
}

bool supported(const Table& t, sampler::Measure) {
  std::vector<sampler::Axis> views;
  for (const GridAxis& g : t.axes) views.push_back(g.view());
  return sampler::AxisSampler<float>::supports(views.data(), static_cast<int>(views.size()));
}

}  // namespace

std::optional<sampler::Measure> sampled_measure(const Table& t) {
  if (t.axes.size() < 2 || t.size() != grid_values(t.axes)) return std::nullopt;
  const bool material = t.group.rfind("materials/", 0) == 0;
  const std::string& last = t.axes.back().name;
  if (t.quantity == "N_p" && last == "phi" && (t.group == "np" || (material && t.name.rfind("np_", 0) == 0))) return sampler::Measure::plain;
  if (t.quantity == "M_p" && last == "theta_r" && (t.group == "mp" || (material && t.name.rfind("mp_", 0) == 0))) return sampler::Measure::cosine;
  return std::nullopt;
}

std::string sampling_path(const Table& t, const std::string& what) { return "sampling/" + t.group + "/" + t.name + "_" + what; }

std::vector<Table> sampling_tables(const TableSet& set, int threads, const SamplingProgress& progress) {
  std::vector<Table> out;
  std::vector<std::pair<const Table*, sampler::Measure>> sampled;
  for (const Table& t : set.tables)
    if (const auto m = sampled_measure(t); m && supported(t, *m)) sampled.emplace_back(&t, *m);
  const std::string_view stage = "sampling data";
  if (progress && !sampled.empty()) progress(stage, 0, sampled.size());
  for (std::size_t done = 0; done < sampled.size(); ++done) {
    const Table& t = *sampled[done].first;
    const std::optional<sampler::Measure> m = sampled[done].second;
    std::vector<double> cdf, mass;
    std::vector<float> bound;
    build(t, *m, cdf, mass, bound, threads);
    if (progress) progress(stage, done + 1, sampled.size());
    const bool cosine = *m == sampler::Measure::cosine;
    const std::string axis = t.axes.back().name;
    nlohmann::ordered_json attrs = {{"sampling_of", t.path()}, {"sampled_axis", axis}, {"measure", cosine ? "cos" : "plain"}};
    if (t.attributes.contains("lobe")) attrs["lobe"] = t.attributes["lobe"];
    std::vector<GridAxis> other(t.axes.begin(), t.axes.end() - 1);
    auto make = [&](const std::string& what, const std::string& quantity, const std::string& long_name, std::vector<GridAxis> axes, Precision p) {
      Table s;
      s.group = "sampling/" + t.group;
      s.name = t.name + "_" + what;
      s.quantity = quantity;
      s.units = "1";
      s.long_name = long_name;
      s.axes = std::move(axes);
      s.attributes = attrs;
      s.precision = p;
      return s;
    };
    const std::string density = std::string("max(0, interpolated ") + t.path() + ")" + (cosine ? " cos theta_r" : "");
    Table c = make("cdf", "sampling_cdf",
                   "prefix integrals over the cells along " + axis + " of each node slice's own interpolant (unclamped" +
                       (cosine ? ", times cos theta_r" : "") + ")" + (axis == "phi" ? ", over [0, pi]" : ""),
                   t.axes, Precision::float64);
    c.f64 = std::move(cdf);
    Table s = make("mass", "sampling_mass", "integral of each node slice's interpolant over the whole " + axis + " domain" + (cosine ? ", times cos theta_r" : ""),
                   other, Precision::float64);
    s.f64 = std::move(mass);
    Table k = make("clamp_bound", "sampling_clamp_bound",
                   "per cell of the other axes (at its first node) and cell along " + axis + " (at its first node): a bound of what the clamp in " +
                       density + " adds to the cell's integral (0: never clamped there)",
                   t.axes, Precision::float32);
    k.f32 = std::move(bound);
    out.push_back(std::move(c));
    out.push_back(std::move(s));
    out.push_back(std::move(k));
  }
  // In the order in which the OpenEXR writer packs tables of one group, quantity and axes (up to
  // four, without a channel axis) into the channels of one part, so that the file's parts read back
  // in the set's order.
  std::vector<std::vector<std::size_t>> packs;
  auto has_channel = [](const Table& t) {
    return std::any_of(t.axes.begin(), t.axes.end(), [](const GridAxis& a) { return a.name == "channel"; });
  };
  for (std::size_t i = 0; i < out.size(); ++i) {
    const Table& t = out[i];
    bool placed = false;
    if (!has_channel(t))
      for (auto& p : packs) {
        const Table& first = out[p.front()];
        if (!has_channel(first) && p.size() < 4 && first.group == t.group && first.quantity == t.quantity && first.axes.size() == t.axes.size() &&
            std::equal(first.axes.begin(), first.axes.end(), t.axes.begin(), [](const GridAxis& a, const GridAxis& b) { return a.to_json() == b.to_json(); })) {
          p.push_back(i);
          placed = true;
          break;
        }
      }
    if (!placed) packs.push_back({i});
  }
  std::vector<Table> ordered;
  for (const auto& p : packs)
    for (std::size_t i : p) ordered.push_back(std::move(out[i]));
  return ordered;
}

void append_sampling_tables(TableSet& set, int threads, const SamplingProgress& progress) {
  std::vector<Table> add = sampling_tables(set, threads, progress);
  for (Table& t : add) set.tables.push_back(std::move(t));
}

namespace {
// The stored arrays of t's sampling data, checked for precision and shape only.
sampler::AxisData stored_arrays(const TableSet& set, const Table& t) {
  sampler::AxisData d;
  const Table* c = set.find(sampling_path(t, "cdf"));
  const Table* m = set.find(sampling_path(t, "mass"));
  const Table* k = set.find(sampling_path(t, "clamp_bound"));
  if (!c || !m || !k) return d;
  const std::size_t n = grid_values(t.axes), slices = n / static_cast<std::size_t>(t.axes.back().count);
  if (c->precision != Precision::float64 || m->precision != Precision::float64 || k->precision != Precision::float32 || c->f64.size() != n ||
      m->f64.size() != slices || k->f32.size() != n)
    return d;
  d.cdf = c->f64.data();
  d.mass = m->f64.data();
  d.clamp_bound = k->f32.data();
  return d;
}
}  // namespace

sampler::AxisData stored_sampling_data(const TableSet& set, const Table& t) {
  const sampler::AxisData d = stored_arrays(set, t);
  if (!d.cdf) return d;
  const std::size_t n = grid_values(t.axes);
  // Trusted only when they are this table's (a checksum proves the file unchanged, not that its
  // sampling data describe its values): otherwise the sampler computes its own.
  const auto measure = sampled_measure(t);
  std::vector<sampler::Axis> axes;
  for (const GridAxis& a : t.axes) axes.push_back(a.view());
  const int dims = static_cast<int>(axes.size());
  bool ok = false;
  if (measure && t.precision == Precision::float32 && t.f32.size() == n)
    ok = sampler::AxisSampler<float>(t.f32.data(), axes.data(), dims, *measure, d).matches(d);
  else if (measure && t.precision == Precision::float64 && t.f64.size() == n)
    ok = sampler::AxisSampler<double>(t.f64.data(), axes.data(), dims, *measure, d).matches(d);
  return ok ? d : sampler::AxisData();
}

namespace {
// t's stored data (d) against the sampler's own, slice by slice and one row of clamp bounds at a
// time, so that a check holds a few rows beside the set, whatever the table's size.
template <class T>
void compare_stored(const Table& t, const T* data, sampler::Measure m, const sampler::AxisData& d, int threads, SamplingDataCheck& r) {
  std::vector<sampler::Axis> views;
  for (const GridAxis& g : t.axes) views.push_back(g.view());
  const sampler::AxisSampler<T> s(data, views.data(), static_cast<int>(views.size()), m, typename sampler::AxisSampler<T>::BlendOnly());
  const std::size_t n = static_cast<std::size_t>(t.axes.back().count);
  // A NaN difference counts as infinite (std::max would drop it).
  auto worse = [](double& worst, double diff) { worst = diff == diff ? std::max(worst, diff) : HUGE_VAL; };
  std::vector<double> cdf(n);
  for (std::size_t slice = 0; slice < s.slices(); ++slice) {
    const double mass = s.slice_prefix(slice, cdf.data());
    // Differences relative to the slice's own scale: the largest |prefix| along it.
    double scale = 0.0;
    for (std::size_t k = 0; k < n; ++k) scale = std::max(scale, std::fabs(cdf[k]));
    const double norm = scale > 0.0 ? scale : 1.0;
    for (std::size_t k = 0; k < n; ++k) worse(r.max_cdf_difference, std::fabs(cdf[k] - d.cdf[slice * n + k]) / norm);
    worse(r.max_mass_difference, std::fabs(mass - d.mass[slice]) / norm);
  }
  // Clamp bounds: the rows the sampler computes against the stored ones; every other stored entry
  // (slices that start no cell, entry n − 1) must be 0 as the sampler's are. Counted as the stored
  // entries that are not 0 (NaN included) less those the compared rows account for.
  std::atomic<std::size_t> mismatches{0}, nonzero_in_rows{0}, clamped_rows{0};
  s.for_each_clamp_bound_row(
      [&](std::size_t first, const float* b) {
        std::size_t bad = 0, nonzero = 0;
        bool clean = true;
        for (std::size_t k = 0; k + 1 < n; ++k) {
          const float stored = d.clamp_bound[first * n + k];
          if (!(b[k] == stored) && !(b[k] != b[k] && stored != stored)) ++bad;
          if (!(stored == 0.0f)) ++nonzero;
          clean = clean && b[k] == 0.0f;
        }
        mismatches += bad, nonzero_in_rows += nonzero;
        if (!clean) ++clamped_rows;
      },
      OmpBlocks{threads});
  std::size_t nonzero_stored = 0;
  for (std::size_t slice = 0; slice < s.slices(); ++slice)
    for (std::size_t k = 0; k + 1 < n; ++k) nonzero_stored += d.clamp_bound[slice * n + k] == 0.0f ? 0 : 1;
  r.bound_mismatches = mismatches + (nonzero_stored - nonzero_in_rows);
  r.cells = 1;
  for (std::size_t a = 0; a + 1 < t.axes.size(); ++a) r.cells *= static_cast<std::size_t>(sampler::axis_cells(t.axes[a].view()));
  r.unclamped = r.cells - std::min<std::size_t>(r.cells, clamped_rows);
}
}  // namespace

std::vector<SamplingDataCheck> check_sampling_data(const TableSet& set, int threads) {
  std::vector<SamplingDataCheck> out;
  for (const Table& t : set.tables) {
    const auto m = sampled_measure(t);
    if (!m || !supported(t, *m)) continue;
    SamplingDataCheck r;
    r.table = t.path();
    const sampler::AxisData d = stored_arrays(set, t);  // compared below even where the sampler would not use them
    if (!d.cdf) {
      r.present = set.find(sampling_path(t, "cdf")) || set.find(sampling_path(t, "mass")) || set.find(sampling_path(t, "clamp_bound"));
      r.problem = r.present ? "stored sampling data have the wrong precision or shape" : "no stored sampling data";
      out.push_back(r);
      continue;
    }
    r.present = true;
    if (t.precision == Precision::float32) compare_stored(t, t.f32.data(), *m, d, threads, r);
    else compare_stored(t, t.f64.data(), *m, d, threads, r);
    out.push_back(r);
  }
  return out;
}

}  // namespace hairlut
