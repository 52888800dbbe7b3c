// Internal: the config parser's pieces, shared by its files: config.cpp (the document: fiber, lobes,
// quadrature, output, the normalized form), config_axes.cpp (axes and per-lobe values) and
// config_tables.cpp (np, mp, dual_scattering, engine, scene; the models of lib/models/ and the kinds of lib/kinds/ parse their own).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hairlut/bake/config.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut::detail::config_parse {

// Thrown inside the parser with a key path; turned into "<source>: <path>: <reason>".
struct KeyError {
  std::string path, reason;
};

[[noreturn]] inline void fail(const std::string& path, const std::string& reason) { throw KeyError{path, reason}; }

// Runs a library validation that throws DomainError whose message starts with the key path.
template <class F>
void checked(F&& f) {
  try {
    f();
  } catch (const DomainError& e) {
    const std::string m = e.what();
    const auto space = m.find(' ');
    fail(m.substr(0, space), space == std::string::npos ? m : m.substr(space + 1));
  }
}

double get_number(const nlohmann::json& j, const char* key, double fallback);

// An angle or value axis of the config (schema-checked) to a GridAxis (semantics checked here).
GridAxis make_axis(const nlohmann::json& j, const std::string& path, const std::string& name, bool angle, double domain_lo,
                   double domain_hi, const std::string& units, const std::string& long_name);
GridAxis make_phi_axis(const nlohmann::json& j, const std::string& path);
// Lobe names → p, with the residual as -1.
int lobe_index(const std::string& name, int lobe_count, const std::string& path);
// Per-lobe values given for some lobes: lobes not listed take the nearest listed lower lobe's
// value (else the nearest higher); the residual takes its own or the highest lobe's.
void per_lobe_values(const nlohmann::json& j, const std::string& path, int lobe_count, double scale, std::vector<double>& out,
                     double& residual_out);
nlohmann::json axes_json(const std::vector<GridAxis>& axes);

// Table kinds: each reads its part of the document into c (doc: the whole document, tables: its "tables").
void parse_np_tables(const nlohmann::json& doc, const nlohmann::json& tables, BakeConfig& c);
void parse_mp_tables(const nlohmann::json& doc, const nlohmann::json& tables, BakeConfig& c);
void parse_scene(const nlohmann::json& doc, BakeConfig& c);
DualScatteringTablesConfig parse_dual_scattering(const nlohmann::json& j, int lobe_count, bool residual);
EngineConfig parse_engine(const nlohmann::json& j, const std::vector<std::string>& lobe_names);
nlohmann::json dual_scattering_json(const DualScatteringTablesConfig& d);
nlohmann::json engine_json(const EngineConfig& e);

}  // namespace hairlut::detail::config_parse
