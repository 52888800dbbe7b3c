#include "hairlut/bake/sampled_error.hpp"

// half's conversions inline (bit shifts, the same values as libImath's table): this layer links no
// OpenEXR or Imath library.
#define IMATH_HALF_NO_LOOKUP_TABLE
#include <Imath/half.h>
#include <omp.h>

#include <algorithm>
#include <cmath>

#include "hairlut/util/error.hpp"

namespace hairlut {
namespace {

constexpr std::size_t kLinesPerSlab = 4;
constexpr std::size_t kPointsPerLine = 8;
constexpr std::size_t kPointsPerSlab = kLinesPerSlab * kPointsPerLine;
constexpr int kPeakGrid = 129;
constexpr int kGoldenSteps = 28;

std::uint64_t mix(std::uint64_t z) {  // splitmix64 finalizer
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

struct Random {
  std::uint64_t state;
  double uniform() {  // [0, 1)
    state += 0x9e3779b97f4a7c15ULL;
    return static_cast<double>(mix(state) >> 11) * 0x1.0p-53;
  }
};

// The domain measured along an axis: its range, except that a θd axis ending within 2° short of
// 90° is measured up to 90° (a renderer asks up to grazing; beyond the last node it reads that
// node, or the limit where the table stores E / cos^n θd). Axes of smaller ranges are subsets the
// config chose.
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

// Largest |f| along axis k over [lo, hi] with the other coordinates of x: a grid, then golden
// section on the two cells around the grid's largest value.
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

struct Sample {
  std::vector<double> x;
  double sampled, exact, denominator, rel, rel_half;
};

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

// ---------------------------------------------------------------------------------------------
// The worst-point search: points where uniform random points rarely land (the first and last cell
// of each axis, the corners, known features, grazing ends), then coordinate search from the worst.

// The value of a point: its error against the truth, with the denominator of its line. Keeps the
// slab's functions and the line's denominator while they apply (one per task, not shared).
class PointEval {
 public:
  PointEval(const PointFunction& sampled, const TableTruth& truth) : sampled_(sampled), truth_(truth) {
    white_ = truth.white_floor > 0.0 && static_cast<bool>(truth.make_white);
  }
  Sample operator()(const std::vector<double>& x) {
    bool new_slab = f_ == nullptr;
    for (int k : truth_.slab_axes) new_slab = new_slab || x[static_cast<std::size_t>(k)] != slab_[static_cast<std::size_t>(k)];
    if (new_slab) {
      slab_ = x;
      f_ = truth_.make(x);
      fw_ = white_ ? truth_.make_white(x) : PointFunction();
      pf_ = truth_.peak_axis >= 0 && truth_.make_fast ? truth_.make_fast(x, false) : f_;
      pfw_ = truth_.peak_axis >= 0 && truth_.make_fast && white_ ? truth_.make_fast(x, true) : fw_;
      line_.clear();
    }
    Sample p;
    p.x = x;
    p.exact = f_(x);
    p.sampled = sampled_(x);
    if (truth_.peak_axis >= 0) {
      std::vector<double> line = x;
      line[static_cast<std::size_t>(truth_.peak_axis)] = 0.0;
      if (line != line_) {
        line_ = line;
        den_ = std::max(peak_along(pf_, x, truth_.peak_axis, truth_.peak_lo, truth_.peak_hi), truth_.absolute_floor);
        if (white_) den_ = std::max(den_, truth_.white_floor * peak_along(pfw_, x, truth_.peak_axis, truth_.peak_lo, truth_.peak_hi));
      }
      p.denominator = den_;
    } else {
      p.denominator = std::max(std::abs(p.exact), truth_.absolute_floor);
      if (white_) p.denominator = std::max(p.denominator, truth_.white_floor * std::abs(fw_(x)));
    }
    p.rel = std::abs(p.sampled - p.exact) / p.denominator;
    if (!std::isfinite(p.rel)) p.rel = std::isnan(p.sampled) || std::isinf(p.sampled) ? HUGE_VAL : 0.0;
    p.rel_half = 0.0;
    return p;
  }

 private:
  const PointFunction& sampled_;
  const TableTruth& truth_;
  bool white_ = false;
  std::vector<double> slab_, line_;
  PointFunction f_, fw_, pf_, pfw_;
  double den_ = 0.0;
};

bool searchable(const GridAxis& a) { return !on_nodes(a) && a.spacing != Spacing::explicit_values && a.hi > a.lo; }

// The end region of an axis: [lo, second node] or [last but one node, hi].
std::pair<double, double> end_region(const GridAxis& a, bool last) {
  const auto n = a.nodes();
  if (n.size() < 2) return {a.lo, a.lo};
  if (a.wrap == Wrap::periodic) return last ? std::pair{n.back(), a.hi} : std::pair{a.lo, n.front() > a.lo ? n.front() : n[1]};
  return last ? std::pair{n[n.size() - 2], domain_hi(a)} : std::pair{a.lo, n[1]};
}

// A point between the end and the inner bound of an end region at fraction d from the end (in
// the axis's mapped coordinate, so that a log axis is searched in log).
double toward(const GridAxis& a, bool last, double d) {
  const auto [lo, hi] = end_region(a, last);
  const double t0 = sampler::mapped(a.spacing, last ? hi : lo), t1 = sampler::mapped(a.spacing, last ? lo : hi);
  return std::clamp(sampler::unmapped(a.spacing, t0 + d * (t1 - t0)), a.lo, domain_hi(a));
}

// The local cell width of axis a at x (in x).
double cell_width(const GridAxis& a, double x) {
  const auto n = a.nodes();
  if (n.size() < 2) return a.hi - a.lo;
  const auto it = std::upper_bound(n.begin(), n.end(), x);
  const std::size_t i = std::clamp<std::size_t>(static_cast<std::size_t>(it - n.begin()), 1, n.size() - 1);
  return std::abs(n[i] - n[i - 1]);
}

using Task = std::vector<std::vector<double>>;  // points sharing a slab (evaluated in order by one thread)

// Evaluates the tasks in parallel; their samples in task order (the same for any thread count).
std::vector<Sample> run_tasks(const std::vector<Task>& tasks, const Table& t, const PointFunction& sampled, const TableTruth& truth, int threads,
                              const SampledErrorOptions& opt) {
  std::vector<std::vector<Sample>> parts(tasks.size());
  std::atomic<bool> failed{false};
  std::string failure;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (failed.load() || (opt.cancel && opt.cancel->load())) continue;
    try {
      PointEval eval(sampled, truth);
      for (const auto& x : tasks[i]) parts[i].push_back(eval(x));
    } catch (const std::exception& e) {
      if (!failed.exchange(true)) {
#pragma omp critical(hairlut_sampled_error)
        failure = e.what();
      }
    }
  }
  if (failed) throw DomainError(t.path() + ": " + failure);
  std::vector<Sample> out;
  for (auto& p : parts) std::move(p.begin(), p.end(), std::back_inserter(out));
  return out;
}

SearchStage stage_of(const std::string& name, const std::vector<Sample>& s) {
  SearchStage st;
  st.name = name;
  st.points = s.size();
  double worst = -1.0;
  for (const Sample& p : s)
    if (p.rel > worst) worst = p.rel, st.worst = p.rel, st.at = p.x;
  return st;
}

// A random point of the table's domain.
std::vector<double> random_point(const Table& t, Random& rng) {
  std::vector<double> x(t.axes.size());
  for (std::size_t k = 0; k < x.size(); ++k) x[k] = draw(t.axes[k], rng);
  return x;
}

// Lines through random points with the points of a line along the peak axis (`along`, or random
// values when empty); without a peak axis, every point random but for the coordinates `fix` sets.
template <class Fix>
void add_lines(std::vector<Task>& tasks, const Table& t, const TableTruth& truth, Random& rng, int lines, const std::vector<double>& along,
               int per_line, Fix fix) {
  for (int l = 0; l < lines; ++l) {
    Task task;
    std::vector<double> x = random_point(t, rng);
    fix(x);
    if (truth.peak_axis >= 0) {
      const auto pk = static_cast<std::size_t>(truth.peak_axis);
      if (!along.empty())
        for (double v : along) x[pk] = v, task.push_back(x);
      else
        for (int j = 0; j < per_line; ++j) {
          // Only the peak coordinate changes along a line (one denominator per line).
          std::vector<double> y = x;
          y[pk] = draw(t.axes[pk], rng);
          fix(y);
          x[pk] = y[pk];
          task.push_back(x);
        }
    } else {
      for (int j = 0; j < per_line; ++j) {
        for (std::size_t k = 0; k < x.size(); ++k)
          if (std::find(truth.slab_axes.begin(), truth.slab_axes.end(), static_cast<int>(k)) == truth.slab_axes.end()) x[k] = draw(t.axes[k], rng);
        fix(x);
        task.push_back(x);
      }
    }
    tasks.push_back(std::move(task));
  }
}

constexpr double kEndFractions[] = {0.0, 1.0 / 1024, 1.0 / 64, 1.0 / 8, 0.25, 0.5, 0.75};
constexpr int kEndFractionCount = 7;

std::vector<SearchStage> worst_point_search(const Table& t, const PointFunction& sampled, const TableTruth& truth, const SampledErrorOptions& opt,
                                            int threads, std::vector<Sample>& all) {
  std::vector<SearchStage> stages;
  const std::size_t dims = t.axes.size();
  std::vector<int> axes;
  for (std::size_t k = 0; k < dims; ++k)
    if (searchable(t.axes[k])) axes.push_back(static_cast<int>(k));
  Random rng{mix(opt.seed ^ 0x5ea4c4ULL)};
  auto in_end = [&](int k, bool last, Random& r) {
    const double u = r.uniform();
    // Half the points at set fractions of the end cell (the end itself, and ever closer to it),
    // half uniform in the cell.
    const double d = u < 0.5 ? kEndFractions[static_cast<int>(r.uniform() * kEndFractionCount) % kEndFractionCount] : r.uniform();
    return toward(t.axes[static_cast<std::size_t>(k)], last, d);
  };
  const int pk = truth.peak_axis;
  auto run = [&](const std::string& name, const std::vector<Task>& tasks) {
    std::vector<Sample> s = run_tasks(tasks, t, sampled, truth, threads, opt);
    stages.push_back(stage_of(name, s));
    std::move(s.begin(), s.end(), std::back_inserter(all));
  };
  // The first and last cell of every axis, the other coordinates random.
  {
    std::vector<Task> tasks;
    for (int k : axes)
      for (bool last : {false, true}) {
        std::vector<double> along;
        if (k == pk)
          for (int j = 0; j < 16; ++j) along.push_back(in_end(k, last, rng));
        add_lines(tasks, t, truth, rng, 16, along, 8, [&](std::vector<double>& x) {
          if (k != pk) x[static_cast<std::size_t>(k)] = in_end(k, last, rng);
        });
      }
    run("edges", tasks);
  }
  // Every corner: each searchable coordinate in its first or last cell.
  if (!axes.empty() && axes.size() <= 8) {
    std::vector<Task> tasks;
    for (unsigned c = 0; c < (1u << axes.size()); ++c) {
      auto corner = [&](std::vector<double>& x) {
        for (std::size_t i = 0; i < axes.size(); ++i) x[static_cast<std::size_t>(axes[i])] = in_end(axes[i], (c >> i) & 1u, rng);
      };
      add_lines(tasks, t, truth, rng, 4, {}, 8, corner);
    }
    run("corners", tasks);
  }
  // Known features: a dense scan along the peak axis (four points per cell), and the features the
  // truth names (caustics, lobe edges, the specular cone) with points around each within a cell.
  if (pk >= 0 && searchable(t.axes[static_cast<std::size_t>(pk)])) {
    const GridAxis& a = t.axes[static_cast<std::size_t>(pk)];
    std::vector<Task> tasks;
    const auto n = a.nodes();
    std::vector<double> dense;
    for (std::size_t i = 0; i + 1 < n.size(); ++i)
      for (int q = 0; q < 4; ++q) dense.push_back(n[i] + (n[i + 1] - n[i]) * (q + 0.5) / 4.0);
    add_lines(tasks, t, truth, rng, 16, dense, 0, [](std::vector<double>&) {});
    if (truth.features)
      for (int l = 0; l < 32; ++l) {
        std::vector<double> x = random_point(t, rng);
        Task task;
        for (double f : truth.features(x)) {
          const double w = cell_width(a, std::clamp(f, a.lo, a.hi));
          for (double o : {-1.0, -0.5, -0.25, -0.125, 0.0, 0.125, 0.25, 0.5, 1.0}) {
            x[static_cast<std::size_t>(pk)] = std::clamp(f + o * w, a.lo, a.hi);
            task.push_back(x);
          }
        }
        if (!task.empty()) tasks.push_back(std::move(task));
      }
    run("features", tasks);
  }
  // Grazing ends: angle axes that reach within 5 degrees of +-90 degrees, approached geometrically.
  {
    std::vector<Task> tasks;
    for (int k : axes) {
      const GridAxis& a = t.axes[static_cast<std::size_t>(k)];
      if (a.units != "rad") continue;
      for (bool last : {false, true}) {
        const double end = last ? domain_hi(a) : a.lo;
        if (std::abs(std::abs(end) - 1.5707963267948966) > 0.0873) continue;
        std::vector<double> along;
        for (int j = 0; j <= 12; ++j) along.push_back(toward(a, last, std::ldexp(1.0, -j)));
        along.push_back(end);
        if (k == pk) {
          add_lines(tasks, t, truth, rng, 16, along, 0, [](std::vector<double>&) {});
        } else {
          for (int l = 0; l < 16; ++l) {
            std::vector<double> x = random_point(t, rng);
            Task task;
            for (double v : along) {
              x[static_cast<std::size_t>(k)] = v;
              if (pk >= 0) x[static_cast<std::size_t>(pk)] = draw(t.axes[static_cast<std::size_t>(pk)], rng);
              task.push_back(x);
            }
            tasks.push_back(std::move(task));
          }
          // The features followed into the grazing end: a ridge along both angles (M_p's specular
          // cone, θr ≈ α − θi) is narrow across the diagonal, so random points on the peak axis
          // miss where it meets the corner.
          if (pk >= 0 && truth.features && searchable(t.axes[static_cast<std::size_t>(pk)])) {
            const GridAxis& pa = t.axes[static_cast<std::size_t>(pk)];
            for (int l = 0; l < 4; ++l) {
              std::vector<double> x = random_point(t, rng);
              Task task;
              for (double v : along) {
                x[static_cast<std::size_t>(k)] = v;
                for (double f : truth.features(x)) {
                  const double w = cell_width(pa, std::clamp(f, pa.lo, pa.hi));
                  for (double o : {-0.5, -0.25, 0.0, 0.25, 0.5}) {
                    x[static_cast<std::size_t>(pk)] = std::clamp(f + o * w, pa.lo, pa.hi);
                    task.push_back(x);
                  }
                }
              }
              if (!task.empty()) tasks.push_back(std::move(task));
            }
          }
        }
      }
    }
    if (!tasks.empty()) run("grazing", tasks);
  }
  // Local maximisation: coordinate search in the mapped coordinates from the worst points found
  // in distinct cells, steps from a quarter cell halved until a millionth of a cell.
  if (!axes.empty() && opt.climb_starts > 0) {
    std::vector<const Sample*> order;
    for (const Sample& p : all) order.push_back(&p);
    std::stable_sort(order.begin(), order.end(), [](const Sample* a, const Sample* b) { return a->rel > b->rel; });
    std::vector<Sample> starts;
    std::vector<std::vector<int>> cells;
    for (const Sample* p : order) {
      if (static_cast<int>(starts.size()) >= opt.climb_starts || !(p->rel > 0.0)) break;
      std::vector<int> c;
      for (std::size_t k = 0; k < dims; ++k) c.push_back(on_nodes(t.axes[k]) ? 0 : cell_of(t.axes[k], p->x[k]));
      if (std::find(cells.begin(), cells.end(), c) != cells.end()) continue;
      cells.push_back(c);
      starts.push_back(*p);
    }
    std::vector<std::vector<Sample>> parts(starts.size());
    std::atomic<bool> failed{false};
    std::string failure;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (std::size_t s = 0; s < starts.size(); ++s) {
      if (failed.load() || (opt.cancel && opt.cancel->load())) continue;
      try {
        PointEval eval(sampled, truth);
        Sample best = starts[s];
        std::vector<double> step(dims, 0.0), tlo(dims), thi(dims);
        for (int k : axes) {
          const GridAxis& a = t.axes[static_cast<std::size_t>(k)];
          const double t0 = sampler::mapped(a.spacing, a.lo), t1 = sampler::mapped(a.spacing, domain_hi(a));
          tlo[static_cast<std::size_t>(k)] = std::min(t0, t1), thi[static_cast<std::size_t>(k)] = std::max(t0, t1);
          step[static_cast<std::size_t>(k)] = 0.25 * std::abs(t1 - t0) / std::max(1, a.count - 1);
        }
        // The peak axis first: moving along it keeps the line's denominator.
        std::vector<int> order_axes = axes;
        std::stable_partition(order_axes.begin(), order_axes.end(), [&](int k) { return k == pk; });
        int evaluations = 0, halvings = 0;
        while (evaluations < opt.climb_evaluations && halvings < 20) {
          bool moved = false;
          for (int k : order_axes) {
            const auto kk = static_cast<std::size_t>(k);
            const GridAxis& a = t.axes[kk];
            for (double sign : {1.0, -1.0}) {
              if (evaluations >= opt.climb_evaluations) break;
              std::vector<double> y = best.x;
              const double tv = std::clamp(sampler::mapped(a.spacing, y[kk]) + sign * step[kk], tlo[kk], thi[kk]);
              y[kk] = std::clamp(sampler::unmapped(a.spacing, tv), a.lo, domain_hi(a));
              if (y[kk] == best.x[kk]) continue;
              Sample q = eval(y);
              ++evaluations;
              const bool better = q.rel > best.rel;
              parts[s].push_back(q);
              if (better) {
                best = std::move(q);
                moved = true;
                break;
              }
            }
          }
          if (!moved) {
            for (double& v : step) v *= 0.5;
            ++halvings;
          }
        }
      } catch (const std::exception& e) {
        if (!failed.exchange(true)) {
#pragma omp critical(hairlut_sampled_error)
          failure = e.what();
        }
      }
    }
    if (failed) throw DomainError(t.path() + ": " + failure);
    std::vector<Sample> s;
    for (auto& p : parts) std::move(p.begin(), p.end(), std::back_inserter(s));
    stages.push_back(stage_of("climb", s));
    std::move(s.begin(), s.end(), std::back_inserter(all));
  }
  return stages;
}

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
