// libFuzzer target: arbitrary bytes as an HDF5 table file (opened as an in-memory file image).
// Valid outcomes are a loaded table set or an IoError; anything else is a bug.
#include <cstddef>
#include <cstdint>
#include <hairlut/io/hdf5_io.hpp>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const hairlut::TableSet set = hairlut::read_hdf5_memory(reinterpret_cast<const char*>(data), size, "fuzz.h5");
    (void)set;
  } catch (const hairlut::IoError& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) __builtin_trap();
  }
  return 0;
}
