// Internal: pieces of the baker shared by the models' bake functions (d'Eon 2011's stages, and
// lib/models/marschner2003/ which includes it as "bake/bake_internal.hpp").
#pragma once

#include <omp.h>

#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "hairlut/bake/bake.hpp"
#include "hairlut/tables/table_sampling.hpp"
#include "hairlut/util/error.hpp"
#include "hairlut/util/version.hpp"

namespace hairlut::detail {

// Runs body(k) for k in [0, n) on the configured threads with dynamic scheduling, reports
// progress from one thread at a time, stops at the cancellation flag and rethrows the first
// exception after the loop. The work items are independent, so the result does not depend on the
// thread count.
template <class Body>
void parallel_for(std::size_t n, const BakeOptions& opt, std::string_view stage, std::size_t weight, Body&& body) {
  std::atomic<std::size_t> done{0};
  std::exception_ptr error;
  std::mutex report_mutex;
  const int threads = opt.threads > 0 ? opt.threads : omp_get_max_threads();
  const auto total = n * weight;
  if (opt.progress) opt.progress(stage, 0, total);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (std::size_t k = 0; k < n; ++k) {
    if (error || (opt.cancel && opt.cancel->load(std::memory_order_relaxed))) continue;
    try {
      body(k);
    } catch (...) {
      std::lock_guard<std::mutex> lock(report_mutex);
      if (!error) error = std::current_exception();
    }
    const std::size_t d = (done += 1) * weight;
    if (opt.progress && report_mutex.try_lock()) {
      opt.progress(stage, d, total);
      report_mutex.unlock();
    }
  }
  if (error) std::rethrow_exception(error);
  if (opt.cancel && opt.cancel->load()) throw BakeCancelled();
  if (opt.progress) opt.progress(stage, total, total);
}

inline Table make_table(std::string group, std::string name, std::string quantity, std::string units, std::string long_name,
                 std::vector<GridAxis> axes, Precision precision, bool allocate = true) {
  Table t;
  t.group = std::move(group);
  t.name = std::move(name);
  t.quantity = std::move(quantity);
  t.units = std::move(units);
  t.long_name = std::move(long_name);
  t.axes = std::move(axes);
  if (allocate) t.allocate(precision);
  else t.precision = precision;  // values produced slab by slab (SlabbedTables)
  return t;
}

inline const GridAxis& axis_named(const std::vector<GridAxis>& axes, const std::string& name) {
  for (const GridAxis& a : axes)
    if (a.name == name) return a;
  throw DomainError("internal: no axis named " + name);
}

// The metadata a model's set opens with (hairlut_version, model, name, description, conventions,
// eta, absorption_path) and closes with (config_hash, config, precision), in the order the files
// keep; the model writes its own keys between the two.
inline void open_set_description(const BakeConfig& c, std::string_view conventions, TableSet& set) {
  set.metadata["hairlut_version"] = kVersion;
  set.metadata["model"] = c.model;
  set.metadata["name"] = c.name;
  set.metadata["description"] = c.description;
  set.metadata["conventions"] = std::string(conventions);
  set.metadata["eta"] = c.eta;
  set.metadata["absorption_path"] = to_string(c.path);
}
inline void close_set_description(const BakeConfig& c, Precision precision, TableSet& set) {
  set.metadata["config_hash"] = c.hash;
  set.metadata["config"] = c.normalized.dump();
  set.metadata["precision"] = precision == Precision::float32 ? "float32" : "float64";
}

// The end of a model's bake after its own tables: the kinds of lib/kinds/, the importance
// sampler's data next to every N_p and M_p table, the time and the notes.
inline TableSet finish_model_bake(const BakeConfig& c, const BakeOptions& opt, std::chrono::steady_clock::time_point t0, Precision precision,
                                  TableSet set, BakeReport& report, BakeReport* report_out) {
  for (const TableKindRequest& k : c.kinds) k.kind->bake(*k.settings, precision, set, report);
  if (c.output.sampling_data) append_sampling_tables(set, opt.threads, opt.progress);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  report.threads = opt.threads;
  set.metadata["notes"] = report.notes;
  if (report_out) *report_out = report;
  return set;
}

}  // namespace hairlut::detail
