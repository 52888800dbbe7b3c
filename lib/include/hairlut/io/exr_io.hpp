// OpenEXR files of hairlut tables, laid out as images an engine can upload as textures.
//
// Tables that share their axes (the lobes of one group) are packed into the channels R, G, B, A
// of one part; a table with a "channel" axis (RGB tables) puts that axis into the channels.
// The remaining axes form a 2D atlas: from the last axis backwards they alternate between x and
// y, the last two forming one tile (for N_p over (beta, sigma_a, theta_d, phi):
// x = phi + n_phi * sigma_a, y = theta_d + n_theta_d * beta). Every part's header describes the
// layout in plain text (hairlut.layout, hairlut.channels, hairlut.axis.<name>) and in full as JSON
// (hairlut.part); the first part also carries the table set's provenance (hairlut.metadata).
// `exrheader FILE` shows all of it.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "hairlut/io/hdf5_io.hpp"  // IoError
#include "hairlut/tables/tables.hpp"

namespace hairlut {

struct ExrWriteOptions {
  bool half = false;               ///< store half floats (values must fit: |v| <= 65504)
  std::string compression = "zip";  ///< none, zip, zips, piz (all lossless)
};

/// Writes the tables as a multi-part EXR file. Throws IoError (also when a value does not fit
/// the half range).
void write_exr(const TableSet& set, const std::filesystem::path& file, const ExrWriteOptions& options = {});

/// Reads an EXR file written by write_exr. Values come back as float32 (half values widened
/// exactly). Throws IoError for files that are not hairlut tables, truncated or corrupted.
TableSet read_exr(const std::filesystem::path& file);

/// The same from bytes in memory (`name` is used in error messages).
TableSet read_exr_memory(const char* data, std::size_t size, const std::string& name);

/// How the tables of a set are grouped into EXR parts (part name → table paths), as write_exr
/// lays them out.
std::vector<std::pair<std::string, std::vector<std::string>>> exr_part_plan(const TableSet& set);

}  // namespace hairlut
