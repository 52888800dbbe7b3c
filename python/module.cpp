// hairlut._core: the C++ side of the Python module. Functions take equal-length 1-D float64
// arrays (hairlut/__init__.py broadcasts) and return numpy arrays; angles are radians, as in the
// library. Long computations release the GIL.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <future>
#include <optional>
#include <hairlut/physics/azimuthal_np.hpp>
#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/physics/directional_albedo.hpp>
#include <hairlut/physics/dual_scattering.hpp>
#include <hairlut/util/error.hpp>
#include <hairlut/physics/hair_model.hpp>
#include <hairlut/physics/lobe_energy.hpp>
#include <hairlut/physics/longitudinal_mp.hpp>
#include <hairlut/bake/np_point.hpp>
#include <hairlut/util/quadrature.hpp>
#include <hairlut/bake/outputs.hpp>
#include <hairlut/io/table_io.hpp>
#include <hairlut/tables/tables.hpp>
#include <hairlut/tables/hair_views.hpp>
#include <hairlut/tables/fourier_tables.hpp>
#include <memory>
#include <hairlut/util/version.hpp>
#include <string>
#include <vector>

namespace py = pybind11;

namespace {

// Array arguments arrive as given and are converted to float64 in values(), so that complex input
// is refused instead of losing its imaginary part in a silent cast.
using Array = py::array;

// The values of a 1-D array of real numbers (checked to have `n` entries when n ≥ 0).
std::vector<double> values(const Array& given, const char* name, py::ssize_t n = -1) {
  if (given.dtype().kind() == 'c')
    throw py::type_error(std::string(name) + " must be real: complex values are refused (their imaginary part would be dropped)");
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(given);
  if (!a) throw py::type_error(std::string(name) + " must be an array of real numbers");
  if (a.ndim() != 1) throw py::value_error(std::string(name) + " must be one-dimensional");
  if (n >= 0 && a.shape(0) != n) throw py::value_error(std::string(name) + " has a different length than the first argument");
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

// A file or directory name without an embedded NUL (the C library would read it as a shorter,
// other name).
const std::string& path_arg(const std::string& s, const char* name) {
  if (s.find('\0') != std::string::npos) throw py::value_error(std::string(name) + " contains a NUL character");
  return s;
}

// How long a long call runs with the GIL released before it checks for a signal (Ctrl-C): Python
// runs its signal handlers only on the main thread with the GIL held, so a call that never comes
// back to check would run to its end, however long.
constexpr auto kSignalCheck = std::chrono::milliseconds(50);

// Runs body(i) for i = 0 … n − 1 on this thread with the GIL released, returning about every
// kSignalCheck to check for signals with the GIL held; a KeyboardInterrupt (or any exception a
// handler raises) ends the loop.
template <class Body>
void interruptible_for(std::size_t n, Body&& body) {
  std::size_t i = 0;
  while (i < n) {
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    py::gil_scoped_release release;
    const auto until = std::chrono::steady_clock::now() + kSignalCheck;
    do body(i++);
    while (i < n && std::chrono::steady_clock::now() < until);
  }
}

// Runs work(cancel) on a thread of its own while this thread, the GIL released between checks,
// checks for signals every kSignalCheck. On a signal whose handler raises, it raises `cancel`, waits
// for the work to stop (the work polls the flag) and raises the handler's exception.
template <class Work>
void interruptible_run(Work&& work) {
  std::atomic<bool> cancel{false};
  auto done = std::async(std::launch::async, [&] { work(&cancel); });
  for (;;) {
    {
      py::gil_scoped_release release;
      if (done.wait_for(kSignalCheck) == std::future_status::ready) break;
    }
    if (PyErr_CheckSignals() != 0) {
      py::error_already_set interrupted;  // takes the handler's exception out of the interpreter
      cancel = true;
      {
        py::gil_scoped_release release;
        done.wait();
      }
      // The work's own end (BakeCancelled, or an error it met first) gives way to the interrupt,
      // which is what the caller asked for.
      try {
        done.get();
      } catch (...) {
      }
      throw interrupted;
    }
  }
  done.get();  // the work's own exception, translated as any other
}

// A numeric argument that pybind11 would convert itself (a numpy complex scalar becomes its real
// part with only a ComplexWarning): refused when complex or not numeric, in one line naming it.
template <class T>
T real(const py::object& v, const char* name) {
  if (py::module_::import("numpy").attr("iscomplexobj")(v).cast<bool>())
    throw py::type_error(std::string(name) + ": complex values are refused (the imaginary part would be dropped)");
  try {
    return v.cast<T>();
  } catch (const py::cast_error&) {
    throw py::type_error(std::string(name) + ": real numbers expected, got " + py::repr(v).cast<std::string>());
  }
}

py::array_t<double> to_array(const std::vector<double>& v) {
  py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

hairlut::HairModel model_of(double eta, double sigma_a, const std::string& path, const std::vector<double>& betas,
                            const std::vector<double>& alphas, int lobes, bool residual) {
  hairlut::HairModel m;
  m.eta = eta;
  m.sigma_a = sigma_a;
  m.path = hairlut::parse_absorption_path(path, "path");
  const std::size_t n = static_cast<std::size_t>(std::max(lobes, 0)) + (residual ? 1 : 0);
  auto per_lobe = [&](const std::vector<double>& v, const char* what) {
    if (v.size() == 1) return std::vector<double>(n, v[0]);
    if (v.size() == n) return v;
    throw py::value_error(std::string(what) + " must give one value or one per lobe (" + std::to_string(n) + " including the residual)");
  };
  const auto b = per_lobe(betas, "beta"), a = per_lobe(alphas, "alpha");
  for (std::size_t p = 0; p < n; ++p) {
    const hairlut::LobeParams lp{b[p], b[p], a[p]};
    if (residual && p + 1 == n) m.residual = lp;
    else m.lobes.push_back(lp);
  }
  m.validate();
  return m;
}

// A table set as plain Python objects: metadata as JSON text, tables with values and node
// coordinates as numpy arrays (hairlut/__init__.py wraps them). Each table's values move into
// its array (a capsule owns the vector): no copy, so a set is held once, not twice, while it is
// handed over.
template <class V>
py::array values_array(std::vector<V>&& values, const std::vector<py::ssize_t>& shape) {
  auto* owned = new std::vector<V>(std::move(values));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<V>*>(p); });
  return py::array_t<V>(shape, owned->data(), owner);
}

py::dict to_python(hairlut::TableSet set) {
  py::dict out;
  out["metadata"] = set.metadata.dump();
  py::list tables;
  for (hairlut::Table& t : set.tables) {
    py::dict d;
    d["path"] = t.path();
    d["group"] = t.group;
    d["name"] = t.name;
    d["quantity"] = t.quantity;
    d["units"] = t.units;
    d["long_name"] = t.long_name;
    d["description"] = t.describe().dump();
    std::vector<py::ssize_t> shape;
    py::list dims, coords;
    for (const hairlut::GridAxis& a : t.axes) {
      shape.push_back(a.count);
      dims.append(a.name);
      coords.append(to_array(a.nodes()));
    }
    d["dims"] = dims;
    d["coords"] = coords;
    d["values"] = t.precision == hairlut::Precision::float32 ? values_array(std::move(t.f32), shape) : values_array(std::move(t.f64), shape);
    tables.append(d);
  }
  out["tables"] = tables;
  return out;
}

// Baked tables read as a renderer reads them: the set loaded in C++ and kept alive with the
// runtime that points into it (HairScattering over the generic tables or one material's).
using SharedTables = std::shared_ptr<const hairlut::TableSet>;
struct Scattering {
  SharedTables set;
  hairlut::sampler::HairScattering<float> hair;
  Scattering(SharedTables tables, const std::string& group)
      : set(std::move(tables)),
        hair(group.empty() ? hairlut::hair_scattering<float>(*set) : hairlut::hair_scattering<float>(*set, group)) {}
  // The runtime `from` prepared for one roughness (its tables are no longer read).
  Scattering(const Scattering& from, const hairlut::sampler::Fiber& roughness) : set(from.set), hair(from.hair, roughness) {}
  // f's own loop body, called with the fiber or, for a prepared runtime, with its state built once.
  template <class Body>
  void with_fiber(const hairlut::sampler::Fiber& f, Body body) const {
    if (hair.prepared()) body(hair.fiber(f));
    else body(f);
  }
};

// Arrays of directions, random numbers and points for the runtime bindings, converted to float64
// (the public module refuses complex input before it reaches them).
using Rows = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Rows of three doubles (n × 3, C order) as pointers: one row, or n rows.
const double* row3(const Rows& a, py::ssize_t i, const char* name) {
  if (a.ndim() != 2 || a.shape(1) != 3) throw py::value_error(std::string(name) + " must have shape (n, 3)");
  return a.data() + (a.shape(0) == 1 ? 0 : i) * 3;
}
py::ssize_t rows(const Rows& a, const Rows& b) {
  if (a.ndim() != 2 || b.ndim() != 2) throw py::value_error("directions must have shape (n, 3)");
  if (a.shape(0) != b.shape(0) && a.shape(0) != 1 && b.shape(0) != 1) throw py::value_error("directions have different lengths");
  return std::max(a.shape(0), b.shape(0));
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "hairlut's C++ library (use the hairlut package, which broadcasts arguments)";
  m.attr("version") = hairlut::kVersion;

  // Library errors become ValueError (bad arguments) or OSError (files).
  py::register_exception<hairlut::ConfigError>(m, "ConfigError", PyExc_ValueError);
  py::register_exception<hairlut::DomainError>(m, "DomainError", PyExc_ValueError);
  py::register_exception<hairlut::IoError>(m, "IoError", PyExc_OSError);

  m.def("parse_lobe", [](const std::string& name) { return hairlut::parse_lobe(name, "lobe"); });
  m.def("lobe_name", &hairlut::lobe_name);

  m.def("longitudinal_mp", [](const Array& beta, const Array& alpha, const Array& theta_i, const Array& theta_r) {
    const auto b = values(beta, "beta");
    const auto n = static_cast<py::ssize_t>(b.size());
    const auto a = values(alpha, "alpha", n), ti = values(theta_i, "theta_i", n), tr = values(theta_r, "theta_r", n);
    std::vector<double> out(b.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
      hairlut::require_positive("beta", b[i]);
      out[i] = hairlut::longitudinal_deon_tilted(b[i] * b[i], a[i], ti[i], tr[i]);
    }
    return to_array(out);
  });

  m.def("azimuthal_np",
        [](int p, const Array& phi, const Array& theta_d, const Array& sigma_a, const Array& beta, double eta, const std::string& path,
           const std::string& method, double tolerance, int order, const std::string& variable) {
          const auto f = values(phi, "phi");
          const auto n = static_cast<py::ssize_t>(f.size());
          const auto td = values(theta_d, "theta_d", n), sa = values(sigma_a, "sigma_a", n), b = values(beta, "beta", n);
          const auto ap = hairlut::parse_absorption_path(path, "path");
          if (method != "baker" && method != "adaptive" && method != "gauss-legendre")
            throw py::value_error("method must be baker, adaptive or gauss-legendre (got \"" + method + "\")");
          // Below 1e-6 rad (the smallest beta a config may give) the lobe's Gaussian underflows and
          // the result is NaN: refused instead.
          for (const double x : b)
            if (x < 1e-6) throw py::value_error("beta must be at least 1e-6 rad (got " + py::repr(py::float_(x)).cast<std::string>() + ")");
          std::vector<double> out(f.size()), err(f.size(), 0.0);
          std::optional<hairlut::GaussLegendreRule> rule;
          const auto var = hairlut::parse_integration_variable(variable, "variable");
          if (method == "gauss-legendre") rule.emplace(order);
          interruptible_for(out.size(), [&](std::size_t i) {
            if (method == "baker") {
              out[i] = hairlut::baker_np(eta, ap, td[i], sa[i], p, b[i], f[i], tolerance).value;
            } else {
              const hairlut::AttenuationSlice slice(eta, td[i], sa[i], ap);
              hairlut::require_positive("beta", b[i]);
              if (method == "adaptive") {
                const auto r = hairlut::azimuthal_np_reference(slice, p, b[i], f[i], tolerance);
                out[i] = r.value[0];
                err[i] = r.error[0];
              } else {
                out[i] = hairlut::azimuthal_np(slice, p, b[i], f[i], *rule, var);
              }
            }
          });
          return py::make_tuple(to_array(out), to_array(err));
        });

  m.def("lobe_energies", [](const Array& theta_d, const Array& sigma_a, double eta, const std::string& path, int lobes, bool residual) {
    const auto td = values(theta_d, "theta_d");
    const auto sa = values(sigma_a, "sigma_a", static_cast<py::ssize_t>(td.size()));
    const auto ap = hairlut::parse_absorption_path(path, "path");
    const hairlut::LobeSet set{lobes, residual};
    const auto cols = static_cast<py::ssize_t>(set.size());
    py::array_t<double> out({static_cast<py::ssize_t>(td.size()), cols});
    double* o = out.mutable_data();
    interruptible_for(td.size(), [&](std::size_t i) {
      const auto r = hairlut::lobe_energies_reference(hairlut::AttenuationSlice(eta, td[i], sa[i], ap), set);
      for (py::ssize_t c = 0; c < cols; ++c) o[static_cast<py::ssize_t>(i) * cols + c] = r.value[static_cast<std::size_t>(c)];
    });
    return out;
  });

  m.def("furnace", [](const Array& theta_i, double eta, double sigma_a, const std::string& path, const std::vector<double>& betas,
                      const std::vector<double>& alphas, int lobes, bool residual) {
    const auto ti = values(theta_i, "theta_i");
    const hairlut::HairModel model = model_of(eta, sigma_a, path, betas, alphas, lobes, residual);
    const std::size_t L = model.lobes.size() + (model.residual ? 1 : 0);
    std::vector<double> total(ti.size()), per(ti.size() * L);
    std::vector<bool> converged(ti.size());
    interruptible_for(ti.size(), [&](std::size_t i) {
      const auto r = hairlut::directional_albedo(model, ti[i]);
      total[i] = r.total;
      for (std::size_t p = 0; p < L; ++p) per[i * L + p] = r.per_lobe[p];
      converged[i] = r.converged;
    });
    py::array_t<double> per_lobe({static_cast<py::ssize_t>(ti.size()), static_cast<py::ssize_t>(L)});
    std::copy(per.begin(), per.end(), per_lobe.mutable_data());
    py::dict out;
    out["E"] = to_array(total);
    out["per_lobe"] = per_lobe;
    out["converged"] = py::cast(converged);
    return out;
  });

  m.def("dual_scattering", [](const Array& theta_i, double eta, double sigma_a, const std::string& path, const std::vector<double>& betas,
                              const std::vector<double>& alphas, int lobes, bool residual, double density_factor) {
    const auto ti = values(theta_i, "theta_i");
    const hairlut::HairModel model = model_of(eta, sigma_a, path, betas, alphas, lobes, residual);
    hairlut::DualScatteringOptions o;
    o.density_factor = density_factor;
    std::vector<hairlut::DualScatteringPoint> points(ti.size());
    interruptible_for(ti.size(), [&](std::size_t i) { points[i] = hairlut::dual_scattering(model, ti[i], o); });
    auto column = [&](auto get) {
      std::vector<double> v;
      for (const auto& p : points) v.push_back(get(p));
      return to_array(v);
    };
    py::dict out;
    out["E"] = column([](const auto& p) { return p.energy_total; });
    out["a_f"] = column([](const auto& p) { return p.a_f; });
    out["a_b"] = column([](const auto& p) { return p.a_b; });
    out["alpha_f"] = column([](const auto& p) { return p.alpha_f; });
    out["alpha_b"] = column([](const auto& p) { return p.alpha_b; });
    out["beta_f2"] = column([](const auto& p) { return p.beta_f2; });
    out["beta_b2"] = column([](const auto& p) { return p.beta_b2; });
    out["A_b"] = column([](const auto& p) { return p.backscatter.A_b; });
    out["delta_b"] = column([](const auto& p) { return p.backscatter.delta_b; });
    out["sigma_b"] = column([](const auto& p) { return p.backscatter.sigma_b; });
    std::vector<bool> converged;
    for (const auto& p : points) converged.push_back(p.converged);
    out["converged"] = py::cast(converged);
    return out;
  });

  m.def(
      "bake",
      [](const std::string& config_json, const std::string& source, const std::string& base_dir, int threads, bool write,
         const std::string& output_dir) {
        path_arg(source, "source"), path_arg(base_dir, "base_dir"), path_arg(output_dir, "output_dir");
        // An empty config_json: read the file `source` (JSON errors then name line and column).
        hairlut::BakeConfig config = config_json.empty() ? hairlut::load_config(source)
                                                         : hairlut::parse_config(nlohmann::json::parse(config_json), source, base_dir);
        if (!output_dir.empty()) config.output.directory = output_dir;
        hairlut::TableSet set;
        std::vector<std::string> files;
        // On a thread of its own, so that this one can check for Ctrl-C while it runs: the bake
        // and the writer poll the cancel flag (the writer removes its temporaries).
        interruptible_run([&](const std::atomic<bool>* cancel) {
          hairlut::BakeOptions options;
          options.threads = threads;
          options.cancel = cancel;
          hairlut::BakeReport report;
          set = hairlut::bake(config, options, &report);
          if (write)
            for (const auto& f : hairlut::write_outputs(set, config, report, cancel)) files.push_back(f.string());
        });
        py::dict out = to_python(std::move(set));
        out["files"] = files;
        out["config_hash"] = config.hash;
        return out;
      },
      py::arg("config_json"), py::arg("source"), py::arg("base_dir"), py::arg("threads") = 0, py::arg("write") = false,
      py::arg("output_dir") = "");

  m.def("load_config_file", [](const std::string& file) {
    const hairlut::BakeConfig c = hairlut::load_config(path_arg(file, "file"));
    return py::make_tuple(c.hash, c.normalized.dump());
  });

  m.def("load_tables", [](const std::string& file) {
    path_arg(file, "file");
    hairlut::TableSet set;
    {
      py::gil_scoped_release release;
      set = hairlut::load_tables(file);
    }
    return to_python(std::move(set));
  });

  // The renderer runtime over baked tables (hairlut.TableSet.scattering wraps it).
  py::class_<hairlut::sampler::Fiber>(m, "Fiber")
      .def(py::init([](const py::object& sigma_a_given, const py::object& beta_m_given, const py::object& beta_n_given,
                       const py::object& tilt_given) {
             const auto sigma_a = real<std::vector<double>>(sigma_a_given, "sigma_a");
             const double beta_m = real<double>(beta_m_given, "beta_m"), beta_n = real<double>(beta_n_given, "beta_n"),
                          tilt = real<double>(tilt_given, "tilt");
             if (sigma_a.size() != 3) throw py::value_error("sigma_a must have 3 values (RGB)");
             hairlut::sampler::Fiber f;
             std::copy(sigma_a.begin(), sigma_a.end(), f.sigma_a);
             f.beta_m = beta_m, f.beta_n = beta_n, f.tilt = tilt;
             return f;
           }),
           py::arg("sigma_a"), py::arg("beta_m"), py::arg("beta_n"), py::arg("tilt") = py::float_(0.0))
      .def_property_readonly("sigma_a", [](const hairlut::sampler::Fiber& f) { return std::vector<double>(f.sigma_a, f.sigma_a + 3); })
      .def_readonly("beta_m", &hairlut::sampler::Fiber::beta_m)
      .def_readonly("beta_n", &hairlut::sampler::Fiber::beta_n)
      .def_readonly("tilt", &hairlut::sampler::Fiber::tilt)
      .def("__repr__", [](const hairlut::sampler::Fiber& f) {
        return "Fiber(sigma_a=[" + std::to_string(f.sigma_a[0]) + ", " + std::to_string(f.sigma_a[1]) + ", " + std::to_string(f.sigma_a[2]) +
               "], beta_m=" + std::to_string(f.beta_m) + ", beta_n=" + std::to_string(f.beta_n) + ")";
      });
  m.def("fiber_from_melanin", &hairlut::fiber_from_melanin, py::arg("eumelanin"), py::arg("pheomelanin"), py::arg("beta_m"), py::arg("beta_n"));

  py::class_<Scattering>(m, "Scattering")
      .def("eval",
           [](const Scattering& s, const hairlut::sampler::Fiber& f, const Rows& wo, const Rows& wi) {
             const py::ssize_t n = rows(wo, wi);
             py::array_t<double> out({n, py::ssize_t{3}});
             s.with_fiber(f, [&](const auto& fib) {
               for (py::ssize_t i = 0; i < n; ++i) s.hair.eval(fib, row3(wo, i, "wo"), row3(wi, i, "wi"), out.mutable_data(i, 0));
             });
             return out;
           })
      .def("pdf",
           [](const Scattering& s, const hairlut::sampler::Fiber& f, const Rows& wo, const Rows& wi) {
             const py::ssize_t n = rows(wo, wi);
             py::array_t<double> out(n);
             s.with_fiber(f, [&](const auto& fib) {
               for (py::ssize_t i = 0; i < n; ++i) out.mutable_data()[i] = s.hair.pdf(fib, row3(wo, i, "wo"), row3(wi, i, "wi"));
             });
             return out;
           })
      .def("albedo",
           [](const Scattering& s, const hairlut::sampler::Fiber& f, const Rows& wo) {
             py::array_t<double> out(wo.ndim() == 2 ? wo.shape(0) : 0);
             s.with_fiber(f, [&](const auto& fib) {
               for (py::ssize_t i = 0; i < out.shape(0); ++i) out.mutable_data()[i] = s.hair.albedo(fib, row3(wo, i, "wo"));
             });
             return out;
           })
      .def("prepared",
           [](const Scattering& s, const hairlut::sampler::Fiber& roughness) {
             std::unique_ptr<Scattering> r;
             {
               py::gil_scoped_release release;
               r = std::make_unique<Scattering>(s, roughness);
             }
             if (!r->hair.valid())
               throw hairlut::DomainError("scattering.prepared: cannot prepare this runtime (a material's or a prepared one, or beta_m or beta_n not > 0)");
             return r;
           })
      .def("sample", [](const Scattering& s, const hairlut::sampler::Fiber& f, const Rows& wo, const Rows& u) {
        const py::ssize_t n = rows(wo, u);
        py::array_t<double> wi({n, py::ssize_t{3}}), weight({n, py::ssize_t{3}}), pdf(n);
        py::array_t<int> lobe(n);
        s.with_fiber(f, [&](const auto& fib) {
          for (py::ssize_t i = 0; i < n; ++i) {
            const hairlut::sampler::ScatteringSample r = s.hair.sample(fib, row3(wo, i, "wo"), row3(u, i, "u"));
            std::copy(r.wi, r.wi + 3, wi.mutable_data(i, 0));
            std::copy(r.weight, r.weight + 3, weight.mutable_data(i, 0));
            pdf.mutable_data()[i] = r.pdf;
            lobe.mutable_data()[i] = r.lobe;
          }
        });
        py::dict d;
        d["wi"] = wi, d["weight"] = weight, d["pdf"] = pdf, d["lobe"] = lobe;
        return d;
      });

  // A table set loaded in C++: each table's quantity at points, interpolated as the file declares
  // (with its factor table), and the runtime over its generic tables or one material's.
  py::class_<hairlut::TableSet, std::shared_ptr<hairlut::TableSet>>(m, "Tables")
      .def(py::init([](const std::string& file) {
        path_arg(file, "file");
        auto set = std::make_shared<hairlut::TableSet>();
        {
          py::gil_scoped_release release;
          *set = hairlut::load_tables(file);
        }
        return set;
      }))
      .def("sample",
           [](const hairlut::TableSet& set, const std::string& path, const Rows& x) {
             const hairlut::Table* t = set.find(path);
             if (!t) throw hairlut::DomainError("no table " + path);
             // A Fourier table stands for N_p over its domain (beta, sigma_a, theta_d, phi; the
             // residual's sigma_a, theta_d), read through the runtime's series evaluation.
             const bool fourier = hairlut::is_fourier_table(*t);
             const auto dims = static_cast<py::ssize_t>(fourier ? hairlut::fourier_domain(*t).size() : t->axes.size());
             if (x.ndim() != 2 || x.shape(1) != dims) throw py::value_error("points must have shape (n, " + std::to_string(dims) + ") for " + path);
             const std::function<double(const std::vector<double>&)> series = fourier ? hairlut::fourier_point_function(*t) : nullptr;
             py::array_t<double> out(x.shape(0));
             std::vector<double> at(static_cast<std::size_t>(dims));
             for (py::ssize_t i = 0; i < x.shape(0); ++i) {
               std::copy(x.data(i, 0), x.data(i, 0) + dims, at.begin());
               bool nan = false;
               for (const double v : at) nan = nan || std::isnan(v);
               out.mutable_data()[i] = nan ? std::nan("") : fourier ? series(at) : set.sample_value(*t, at);
             }
             return out;
           })
      .def("domain",
           [](const hairlut::TableSet& set, const std::string& path) {
             // The axes sample() takes for table `path`: its own, or a Fourier table's domain.
             const hairlut::Table* t = set.find(path);
             if (!t) throw hairlut::DomainError("no table " + path);
             const std::vector<hairlut::GridAxis> axes = hairlut::is_fourier_table(*t) ? hairlut::fourier_domain(*t) : t->axes;
             py::list out;
             for (const hairlut::GridAxis& a : axes) out.append(py::str(a.to_json().dump()));
             return out;
           })
      .def("scattering", [](const std::shared_ptr<hairlut::TableSet>& set, const std::string& group) {
        return std::make_unique<Scattering>(set, group);
      }, py::arg("group") = "");
}
