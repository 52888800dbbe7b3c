// The baker's part for tables.dual_scattering (mean energy and dual scattering over generic
// axes) and tables.engine (the Unreal preset's dual scattering and mean energy over its axes; HDRP's
// three textures as its own kernels define them, hdrp_kernels.hpp), called by bake(). The engine textures themselves are written by
// engine_exr.hpp from these tables.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "hairlut/bake/bake.hpp"
#include "hairlut/bake/config.hpp"
#include "hairlut/tables/tables.hpp"

namespace hairlut {

/// Bakes the config's tables.dual_scattering and tables.engine into `set` (tables, metadata) and
/// adds what it did to `report`. Does nothing when the config asks for neither.
/// Throws DomainError, BakeCancelled.
void bake_dual_scattering_tables(const BakeConfig& config, const BakeOptions& options, TableSet& set, BakeReport& report);

/// The roughened azimuthal distribution with unit attenuation,
///   N¹_p(φ; θd, β) = ½ ∫_{−1}^{1} D_β(φ − Φ(p, h)) dh = (1/2π) [c_0 + 2 Σ_{n≥1} e^{−n²β²/2} c_n cos nφ],
///   c_n = ∫_0^{π/2} cos(n Φ(p, γ)) cos γ dγ (c_0 = 1),
/// at every (β, φ) of the lists, out[b · phis.size() + j]; ∫ N¹_p dφ = 1: d'Eon's Gaussian detector
/// with unit attenuation (HDRP's own azimuthal texture uses the trimmed logistic instead,
/// hdrp_kernels.hpp). The series is cut where its tail is
/// below `tolerance` (fourier_terms) and the c_n are integrated by Gauss–Legendre with
/// fourier_nodes(terms, p, geometry, tolerance) nodes. Domain: η > 1, θd in [−π/2, π/2], p ≥ 0,
/// every β > 0 (at most 4e6 terms), finite φ, 0 < tolerance < 1. Values ≥ 0. `rules` (optional)
/// shares Gauss–Legendre rules between calls.
void unit_attenuation_np(double eta, int p, double theta_d, std::span<const double> betas, std::span<const double> phis,
                         double tolerance, std::vector<double>& out, GaussLegendreCache* rules = nullptr);

}  // namespace hairlut
