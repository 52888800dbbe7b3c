# catch_discover_tests registers each Catch2 test case with ctest under its name, and CMake splits
# a name at ';' into two tests that match nothing and "pass" without running. Refuse such names, and
# the same in the names the CMakeLists give add_test (the labels are set over the list of them).
file(GLOB sources "${TEST_DIR}/*.cpp" "${TEST_DIR}/CMakeLists.txt" "${TEST_DIR}/*/CMakeLists.txt")
set(bad "")
foreach(f IN LISTS sources)
  file(STRINGS "${f}" lines REGEX "(TEST_CASE|add_test)\\((NAME )?\"[^\"]*;")
  foreach(l IN LISTS lines)
    string(APPEND bad "${f}: ${l}\n")
  endforeach()
endforeach()
if(bad)
  message(FATAL_ERROR "test case names with ';' never run under ctest:\n${bad}")
endif()
message(STATUS "no test case name contains ';'")
