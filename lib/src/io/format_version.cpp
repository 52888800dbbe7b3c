// The table format version every hairlut file records (hdf5_io.hpp), shared by the HDF5 and
// OpenEXR readers and writers; apart from them so that neither pulls in the other.
#include <algorithm>
#include <string>

#include "hairlut/io/hdf5_io.hpp"

namespace hairlut {

std::string format_version_text() { return std::to_string(kFormatVersionMajor) + "." + std::to_string(kFormatVersionMinor); }

int format_major_of(const TableSet& set) {
  const bool over_grazing = std::any_of(set.tables.begin(), set.tables.end(), [](const Table& t) {
    return t.attributes.contains("cos_theta_d_power") || t.attributes.contains("grazing_absorption");
  });
  return over_grazing ? 3 : 2;
}

std::string format_version_text(const TableSet& set) { return std::to_string(format_major_of(set)) + ".0"; }

int check_format_version(const std::string& text, const std::string& name) {
  const auto dot = text.find('.');
  auto digits = [](const std::string& d) {
    return !d.empty() && d.size() <= 6 && std::all_of(d.begin(), d.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (dot == std::string::npos || !digits(text.substr(0, dot)) || !digits(text.substr(dot + 1)))
    throw IoError(name + ": malformed format version \"" + text.substr(0, 40) + "\" (expected MAJOR.MINOR)");
  const int major = std::stoi(text.substr(0, dot));
  if (major > kFormatVersionMajor)
    throw IoError(name + ": written in table format " + text + ", newer than this hairlut reads (format " + format_version_text() +
                  ", major version " + std::to_string(kFormatVersionMajor) + "); use a newer hairlut");
  if (major < kFormatVersionMajorOldest)
    throw IoError(name + ": written in table format " + text + ", older than this hairlut reads (major versions " +
                  std::to_string(kFormatVersionMajorOldest) + " to " + std::to_string(kFormatVersionMajor) + "); bake the tables again");
  return major;
}

}  // namespace hairlut
