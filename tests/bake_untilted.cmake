# Bakes CONFIG with its lobes' tilts removed, HDF5 only, into OUT (a directory), for the test
# binaries that compare tilted tables with untilted ones: one bake per ctest run, which each of
# their test processes loads (HAIRLUT_TEST_UNTILTED) instead of baking the set again in memory.
# --force: the library may have changed since the last run while the config has not.
# Usage: cmake -DBAKE=bake-hair-luts -DCONFIG=default.json -DOUT=dir -P bake_untilted.cmake
file(READ "${CONFIG}" doc)
string(JSON doc REMOVE "${doc}" lobes tilt_deg)
string(JSON doc SET "${doc}" output formats "[\"hdf5\"]")
string(JSON doc SET "${doc}" output directory "\"${OUT}\"")
file(MAKE_DIRECTORY "${OUT}")
file(WRITE "${OUT}/untilted.json" "${doc}")
execute_process(COMMAND "${BAKE}" --config "${OUT}/untilted.json" --force --quiet RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "bake_untilted: bake-hair-luts exited ${rc} for ${OUT}/untilted.json")
endif()
