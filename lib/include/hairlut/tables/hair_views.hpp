// Typed views of a loaded table set: the d'Eon 2011 N_p, M_p and residual tables of a TableSet as
// sampler::HairTables (hairlut/sampler/sampler_fiber.hpp), built from the set's metadata, so that a user
// looks values up by physical arguments without mapping axis names or attributes by hand.
#pragma once

#include <string_view>

#include "hairlut/sampler/fourier_np.hpp"
#include "hairlut/sampler/hair_scattering.hpp"
#include "hairlut/sampler/sampler_fiber.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// The views of `set`'s tables np/<lobe> (with their `factor` energy tables), np/residual,
/// mp/<lobe> and mp/residual for every lobe its metadata lists. T is the stored type (float for
/// float32 tables, double for float64), R the arithmetic type (float or double). The views point
/// into `set` (its values and explicit axis nodes): `set` must outlive them and stay unchanged.
/// Throws DomainError (naming the table) when the set is not of model deon2011, a table is
/// missing, its axes are not (beta, sigma_a, theta_d, phi) / (sigma_a, theta_d) /
/// (beta, theta_i, theta_r) in that order, a factor table is missing or on other axes, or the
/// tables are not stored as T.
template <class T, class R>
sampler::HairTables<T, R> hair_tables(const TableSet& set);

/// The renderer runtime (eval, sample, pdf; hair_scattering.hpp) over `set`'s d'Eon tables
/// (hair_tables<T, double>), with the N_p tables' sampling data along φ where the file stores them.
/// It points into `set`, which must outlive it. Throws DomainError as hair_tables does, and when a
/// table's sampled axis is one the runtime cannot invert.
template <class T>
sampler::HairScattering<T> hair_scattering(const TableSet& set);
/// The tables of one material of a per-material bake (group "materials/<name>") as the header-only
/// runtime and the GPU texture builder take them: pointers into `set` (which must outlive the
/// result), the grazing factors the values were divided by and the material's σa. Throws
/// DomainError naming the table that is missing, not stored as T or on other axes than the first
/// lobe's.
template <class T>
sampler::MaterialTables<T> material_tables(const TableSet& set, std::string_view group);
/// The material groups of a per-material bake ("materials/<name>"), in the order of their first table.
std::vector<std::string> material_groups(const TableSet& set);
/// The runtime over one table group: "" for the generic tables (as above) or "materials/<name>",
/// whose tables fix σa and β (the runtime copies them; `set` need not outlive it). Throws
/// DomainError naming the table that is missing, on other axes, or on axes the runtime cannot
/// sample exactly (material_scattering.hpp).
template <class T>
sampler::HairScattering<T> hair_scattering(const TableSet& set, std::string_view group);

/// N_p of one lobe of a set baked in the Fourier representation (tables.np.representation
/// "fourier"; fourier_tables.hpp): the view of np_fourier/<lobe> ("R", "TT", ..., or "residual",
/// whose one coefficient gives its uniform N), N_p = view(β, σa, θd, φ). T is the stored type, R
/// the arithmetic type; the view points into `set`, which must outlive it. Throws DomainError
/// (naming the table) when the set has no such table, its attributes or axes are malformed, or it
/// is not stored as T.
template <class T, class R>
sampler::FourierNp<T, R> fourier_np(const TableSet& set, std::string_view lobe);

/// The index p of a lobe in hair_tables(set).np / .mp ("R" → 0, ... as the set's metadata lists
/// them). Throws DomainError naming the lobes the set has.
int lobe_index(const TableSet& set, std::string_view lobe);

/// A fiber from d'Eon 2011's melanin model (σa = c_e (0.419, 0.697, 1.37) + c_p (0.187, 0.4, 1.05),
/// melanin_sigma_a_rgb) and its roughness β_m, β_n [rad]. Throws DomainError for negative or
/// non-finite concentrations or roughness ≤ 0.
sampler::Fiber fiber_from_melanin(double eumelanin, double pheomelanin, double beta_m, double beta_n);

}  // namespace hairlut
