// libFuzzer target: arbitrary bytes as an HDF5 table file, read whole (as an in-memory file
// image) and, from a file, as the validator reads a set in parts: its outline with the checksum
// streamed, and runs of β rows. Valid outcomes are a table set or an IoError; anything else is a
// bug. A file read whole must also pass as an outline, and each run of rows must hold the whole
// table's rows.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <hairlut/io/hdf5_io.hpp>
#include <optional>
#include <string>

namespace {

void one_line(const hairlut::IoError& e) {
  if (std::string(e.what()).find('\n') != std::string::npos) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::optional<hairlut::TableSet> whole;
  try {
    whole = hairlut::read_hdf5_memory(reinterpret_cast<const char*>(data), size, "fuzz.h5");
  } catch (const hairlut::IoError& e) {
    one_line(e);
  }
  static const std::filesystem::path file = std::filesystem::temp_directory_path() / ("hairlut-fuzz-" + std::to_string(::getpid()) + ".h5");
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    (void)hairlut::read_hdf5_outline(file, true, 4096);
  } catch (const hairlut::IoError& e) {
    one_line(e);
    if (whole) __builtin_trap();  // the outline checks no more than the whole read
  }
  for (const int first : {0, 1}) {
    hairlut::Hdf5Rows rows;
    rows.first = first, rows.count = 2;
    try {
      const hairlut::TableSet part = hairlut::read_hdf5_rows(file, rows);
      if (!whole) continue;
      for (const hairlut::Table& t : part.tables) {
        const hairlut::Table* w = whole->find(t.path());
        if (!w) __builtin_trap();
        if (t.group != "np" || t.axes.empty() || t.axes[0].name != "beta") {
          if (t.size() != w->size()) __builtin_trap();
          continue;
        }
        const std::size_t row = w->size() / static_cast<std::size_t>(w->axes[0].count);
        if (t.size() != 2 * row) __builtin_trap();
        for (std::size_t i = 0; i < t.size(); ++i)
          if (!(t.get(i) == w->get(static_cast<std::size_t>(first) * row + i)) && !(t.get(i) != t.get(i))) __builtin_trap();
      }
    } catch (const hairlut::IoError& e) {
      one_line(e);
    }
  }
  return 0;
}
