// The shipped default tables and the same config baked without tilts, each loaded once per test
// process: what the renderer runtime's tests (test_hair_scattering.cpp, test_prepared_scattering.cpp)
// read. Under ctest the untilted set is the file its fixture baked (HAIRLUT_TEST_UNTILTED), else it
// is baked here in memory.
#pragma once

#include <hairlut/bake/bake.hpp>
#include <hairlut/bake/config.hpp>
#include <hairlut/io/table_io.hpp>

#include <cstdlib>
#include <fstream>
#include <string>

namespace test_tables {

inline const hairlut::TableSet& tilted_default() {
  static const hairlut::TableSet set = hairlut::load_tables(std::string(HAIRLUT_SOURCE_DIR) + "/tables/default/hairlut-default.h5");
  return set;
}

inline const hairlut::TableSet& untilted_default() {
  static const hairlut::TableSet set = [] {
    if (const char* file = std::getenv("HAIRLUT_TEST_UNTILTED")) return hairlut::load_tables(file);
    std::ifstream in(std::string(HAIRLUT_SOURCE_DIR) + "/tables/configs/default.json");
    nlohmann::json j = nlohmann::json::parse(in);
    j["lobes"].erase("tilt_deg");
    j["output"]["formats"] = {"hdf5"};
    j["output"]["directory"] = ".";
    hairlut::BakeOptions options;
    options.threads = 2;
    return hairlut::bake(hairlut::parse_config(j, "untilted.json", std::string(HAIRLUT_SOURCE_DIR) + "/tables/configs"), options);
  }();
  return set;
}

}  // namespace test_tables
