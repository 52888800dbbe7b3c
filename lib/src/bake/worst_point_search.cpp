// The worst-point search of the sampled-error measure (sampled_error.hpp): points where uniform
// random points rarely land (the first and last cell of each axis, the corners, known features,
// every cell where the exact value is cheap, grazing ends), then coordinate search from the worst.
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iterator>
#include <string>
#include <vector>

#include "hairlut/util/error.hpp"
#include "sampled_error_detail.hpp"

namespace hairlut::detail::sampled {
namespace {

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

// Runs work(i, eval, out) for i < n in parallel, each with its own PointEval appending to its own
// list, and returns the lists joined in index order (the same for any thread count). The first
// exception stops the rest and is rethrown naming the table.
template <class Work>
std::vector<Sample> parallel_samples(std::size_t n, const Table& t, const PointFunction& sampled, const TableTruth& truth, int threads,
                                     const SampledErrorOptions& opt, Work&& work) {
  std::vector<std::vector<Sample>> parts(n);
  std::atomic<bool> failed{false};
  std::string failure;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (std::size_t i = 0; i < n; ++i) {
    if (failed.load() || (opt.cancel && opt.cancel->load())) continue;
    try {
      PointEval eval(sampled, truth);
      work(i, eval, parts[i]);
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

// Evaluates the tasks in parallel; their samples in task order (the same for any thread count).
std::vector<Sample> run_tasks(const std::vector<Task>& tasks, const Table& t, const PointFunction& sampled, const TableTruth& truth, int threads,
                              const SampledErrorOptions& opt) {
  return parallel_samples(tasks.size(), t, sampled, truth, threads, opt, [&](std::size_t i, PointEval& eval, std::vector<Sample>& out) {
    for (const auto& x : tasks[i]) out.push_back(eval(x));
  });
}
}  // namespace

SearchStage stage_of(const std::string& name, const std::vector<Sample>& s) {
  SearchStage st;
  st.name = name;
  st.points = s.size();
  double worst = -1.0;
  for (const Sample& p : s)
    if (p.rel > worst) worst = p.rel, st.worst = p.rel, st.at = p.x;
  return st;
}

namespace {

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
// The most points the sweep of every cell evaluates in one table (larger grids skip it).
constexpr std::size_t kSweepPoints = std::size_t{1} << 20;
}  // namespace

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
    // Every cell: where the exact quantity is cheap, a scan of the peak axis (two points per
    // cell) at the middle of every cell of the other axes, β only in its first cell, where the
    // lobes are narrowest and interpolation misses most (M_p of the default tables: 144 lines of
    // 432 points). Ridges a cell wide, such as M_p's near the grazing corner, lie between the
    // random points, and the local maximisation climbs only from where points have landed.
    std::vector<double> half;
    for (std::size_t i = 0; i + 1 < n.size(); ++i)
      for (int q = 0; q < 2; ++q) half.push_back(n[i] + (n[i + 1] - n[i]) * (q + 0.5) / 2.0);
    std::size_t lines = 1;
    for (int k : axes) {
      const GridAxis& b = t.axes[static_cast<std::size_t>(k)];
      if (k != pk && b.name != "beta") lines *= static_cast<std::size_t>(std::max(1, b.count - 1));
    }
    if (truth.sweep_cells && lines * half.size() <= kSweepPoints) {
      std::vector<Task> sweep;
      std::vector<double> x = random_point(t, rng);
      for (std::size_t line = 0; line < lines; ++line) {
        std::size_t rest = line;
        for (int k : axes) {
          if (k == pk) continue;
          const GridAxis& b = t.axes[static_cast<std::size_t>(k)];
          const auto nk = b.nodes();
          const std::size_t c = b.name == "beta" ? 0 : rest % (nk.size() - 1);
          if (b.name != "beta") rest /= nk.size() - 1;
          x[static_cast<std::size_t>(k)] = 0.5 * (nk[c] + nk[c + 1]);
        }
        Task task;
        for (double v : half) x[static_cast<std::size_t>(pk)] = v, task.push_back(x);
        sweep.push_back(std::move(task));
      }
      run("cells", sweep);
    }
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
  // in distinct cells, and from the worst point in each cell of the roughness axis β (the error
  // grows as the lobes narrow, and the worst of a narrow-β cell is often a ridge that the overall
  // worst points, all at another β, never climb to), steps from a quarter cell halved until a
  // millionth of a cell.
  if (!axes.empty() && opt.climb_starts > 0) {
    std::vector<const Sample*> order;
    for (const Sample& p : all) order.push_back(&p);
    std::stable_sort(order.begin(), order.end(), [](const Sample* a, const Sample* b) { return a->rel > b->rel; });
    std::vector<Sample> starts;
    std::vector<std::vector<int>> cells;
    auto start_from = [&](const Sample& p) {
      std::vector<int> c;
      for (std::size_t k = 0; k < dims; ++k) c.push_back(on_nodes(t.axes[k]) ? 0 : cell_of(t.axes[k], p.x[k]));
      if (std::find(cells.begin(), cells.end(), c) != cells.end()) return;
      cells.push_back(c);
      starts.push_back(p);
    };
    for (const Sample* p : order) {
      if (static_cast<int>(starts.size()) >= opt.climb_starts || !(p->rel > 0.0)) break;
      start_from(*p);
    }
    for (int k : axes) {
      const GridAxis& a = t.axes[static_cast<std::size_t>(k)];
      if (a.name != "beta") continue;
      std::vector<char> seen(static_cast<std::size_t>(std::max(1, a.count - 1)), 0);
      for (const Sample* p : order) {
        const auto c = static_cast<std::size_t>(cell_of(a, p->x[static_cast<std::size_t>(k)]));
        if (p->rel > 0.0 && c < seen.size() && !seen[c]) seen[c] = 1, start_from(*p);
      }
    }
    std::vector<Sample> s =
        parallel_samples(starts.size(), t, sampled, truth, threads, opt, [&](std::size_t start, PointEval& eval, std::vector<Sample>& part) {
        Sample best = starts[start];
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
              part.push_back(q);
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
        });
    stages.push_back(stage_of("climb", s));
    std::move(s.begin(), s.end(), std::back_inserter(all));
  }
  return stages;
}

}  // namespace hairlut::detail::sampled
