// Baked tables in memory: values on a grid of named axes, with their metadata. What the baker
// produces, the HDF5/EXR writers store and the loaders give back.
#pragma once

#include <nlohmann/json.hpp>
#include <functional>
#include <string>
#include <vector>

#include "hairlut/sampler/sampler_fiber.hpp"
#include "hairlut/tables/grid.hpp"
#include "hairlut/util/hash.hpp"

namespace hairlut {

/// Storage precision of a table's values.
enum class Precision { float32, float64 };

/// One table: row-major values over `axes` (last axis fastest).
struct Table {
  std::string group;      ///< "np", "mp", "melanin", "materials/<name>"
  std::string name;       ///< "R", "TT", "residual", "energy_R", "sigma_a_deon", ...
  std::string quantity;   ///< "N_p", "M_p", "energy", "sigma_a"
  std::string units;      ///< "1/rad", "1", "1/radius"
  std::string long_name;  ///< one-line description
  std::vector<GridAxis> axes;
  nlohmann::ordered_json attributes = nlohmann::ordered_json::object();  ///< lobe, p, tilt, material, ...
  Precision precision = Precision::float32;
  std::vector<float> f32;   ///< the values when precision == float32
  std::vector<double> f64;  ///< the values when precision == float64

  std::string path() const { return group + "/" + name; }
  std::size_t size() const { return precision == Precision::float32 ? f32.size() : f64.size(); }
  /// Allocates grid_size(axes) zeros in the given precision.
  void allocate(Precision p);
  double get(std::size_t i) const { return precision == Precision::float32 ? f32[i] : f64[i]; }
  /// Stores a double, rounded to the table's precision.
  void set(std::size_t i, double v) {
    if (precision == Precision::float32) f32[i] = static_cast<float>(v);
    else f64[i] = v;
  }
  /// The stored values interpolated at x (one coordinate per axis) with the shipped sampler and
  /// each axis's interpolation; never negative for a non-negative quantity (every quantity but
  /// "shift" and "transmittance"); times g(σa, θd) where the table stores its quantity divided by it
  /// (grazing_factor). For the quantity the table stands for (with its factor table), use sample_value.
  double sample(const std::vector<double>& x) const;
  /// g where the values are the quantity divided by g(σa, θd) (attributes "cos_theta_d_power" and
  /// "grazing_absorption", format 3.0: energy and residual tables whose θd axis reaches 90°, where
  /// the energies vanish); none() otherwise.
  sampler::GrazingFactor grazing_factor() const;
  /// Records g in the attributes grazing_factor() reads (nothing for none()).
  void set_grazing_factor(const sampler::GrazingFactor& g);
  /// The table whose value multiplies this one's (attribute "factor", e.g. "np/energy_TT" for N_p
  /// stored as the shape N_p / E_p), or "" when the values are the quantity itself.
  std::string factor() const { return attributes.value("factor", std::string()); }
  /// Table metadata as JSON (everything but the values).
  nlohmann::ordered_json describe() const;
  /// describe() with each axis's entry in "axes" given by `axis_json` (writers that dump the
  /// same axes for many tables put a placeholder there and dump each axis once).
  nlohmann::ordered_json describe(const std::function<nlohmann::ordered_json(const GridAxis&)>& axis_json) const;
};

/// A set of tables and the provenance shared by all of them.
struct TableSet {
  nlohmann::ordered_json metadata = nlohmann::ordered_json::object();  ///< version, config, hash, model, ...
  std::vector<Table> tables;
  /// The table at "group/name", or nullptr.
  const Table* find(const std::string& path) const;
  /// Bytes of all table values.
  std::size_t bytes() const;
  /// The quantity table t stands for at x: t.sample(x), times its factor table sampled at the
  /// coordinates of x on the factor's axes (matched by name). Throws DomainError when the factor
  /// table is missing or has an axis t lacks.
  double sample_value(const Table& t, const std::vector<double>& x) const;
};

/// How values enter content_checksum: as stored in memory, or rounded as a file stores them.
enum class ChecksumRounding { as_stored, float32, half };

/// The hash (hex; XXH3-64 as files of format 2.x record it, or FNV-1a 64 as files of format 1.x
/// do) over the set's metadata, each table's description and its values (as float32 bytes, after
/// half rounding if asked, or as stored). Writers record it and loaders verify it, so a corrupted
/// file is rejected even where the file format has no checksum of its own.
std::string content_checksum(const TableSet& set, ChecksumRounding rounding = ChecksumRounding::as_stored,
                             HashAlgorithm algorithm = kFileHash);

}  // namespace hairlut
