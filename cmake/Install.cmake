# Install rules: the library's layers and their headers, the CMake package (hairlut::runtime, the
# compiled layers hairlut::physics … hairlut::report, the umbrella hairlut::hairlut), a pkg-config
# file, the tools, the schemas and shipped configs, the licence. The package is relocatable:
# `cmake --install build/release --prefix P` works for any P.
include(CMakePackageConfigHelpers)

set(HAIRLUT_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/hairlut CACHE STRING "Where hairlutConfig.cmake is installed (relative to the prefix)")
mark_as_advanced(HAIRLUT_CMAKE_DIR)
# The compiled layers, bottom to top (the order a static link needs them in, reversed).
set(HAIRLUT_LAYERS physics tables formats bake report)
set(_hairlut_layer_targets "")
foreach(_layer IN LISTS HAIRLUT_LAYERS)
  list(APPEND _hairlut_layer_targets hairlut_${_layer})
endforeach()

install(TARGETS ${_hairlut_layer_targets} hairlut EXPORT hairlut-targets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS hairlut_runtime EXPORT hairlut-runtime-targets)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/lib/include/hairlut DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.hpp")
install(FILES ${PROJECT_BINARY_DIR}/lib/generated/hairlut/util/version.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/hairlut/util)
install(EXPORT hairlut-targets NAMESPACE hairlut:: DESTINATION ${HAIRLUT_CMAKE_DIR} FILE hairlut-targets.cmake)
install(EXPORT hairlut-runtime-targets NAMESPACE hairlut:: DESTINATION ${HAIRLUT_CMAKE_DIR} FILE hairlut-runtime-targets.cmake)

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/hairlutConfig.cmake.in ${PROJECT_BINARY_DIR}/hairlutConfig.cmake
                              INSTALL_DESTINATION ${HAIRLUT_CMAKE_DIR})
# Before 1.0 a minor release may change the API: a request for 0.1 accepts 0.1.x only.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/hairlutConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/hairlutConfig.cmake ${PROJECT_BINARY_DIR}/hairlutConfigVersion.cmake DESTINATION ${HAIRLUT_CMAKE_DIR})

# pkg-config: relocatable (prefix from the .pc file's own place). The static layers carry
# undefined references to HDF5 (and its high-level library), OpenEXR, zlib and the OpenMP runtime,
# so every consumer's link needs them: they go into Requires and Libs, not the .private fields that
# only `pkg-config --static` reads. The layers are named top first, as a static link needs them.
# The OpenMP runtime is named by its libraries (libgomp for GCC) rather than -fopenmp, so that a
# one-line compile-and-link does not compile the consumer with OpenMP.
set(HAIRLUT_PC_LIBS "")
set(_hairlut_top_first ${HAIRLUT_LAYERS})
list(REVERSE _hairlut_top_first)
foreach(_layer IN LISTS _hairlut_top_first)
  string(APPEND HAIRLUT_PC_LIBS " -lhairlut_${_layer}")
endforeach()
string(APPEND HAIRLUT_PC_LIBS " -lhdf5_hl")
foreach(_omp_lib IN LISTS OpenMP_CXX_LIB_NAMES)
  string(APPEND HAIRLUT_PC_LIBS " -l${_omp_lib}")
endforeach()
file(RELATIVE_PATH HAIRLUT_PC_TO_PREFIX /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
string(REGEX REPLACE "/$" "" HAIRLUT_PC_TO_PREFIX "${HAIRLUT_PC_TO_PREFIX}")
configure_file(${PROJECT_SOURCE_DIR}/hairlut.pc.in ${PROJECT_BINARY_DIR}/hairlut.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/hairlut.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# share/hairlut mirrors the repository's schemas/ and tables/ (configs and the default tables), so
# that installed tools find their data below it as they find it in a checkout, and the configs'
# "$schema" references resolve.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/schemas/ DESTINATION ${CMAKE_INSTALL_DATADIR}/hairlut/schemas FILES_MATCHING PATTERN "*.json")
# tables/configs holds only configs whose bakes pass their own validator: the starting points.
# generic.json is the benchmark's input (it does not pass its own validator). The configs whose
# bakes do not yet pass theirs (docs/unvalidated-configs.md says which checks fail and why) are
# installed apart, under tables/unvalidated-configs, with that document as its README.md.
set(hairlut_unvalidated_configs engine.json marschner.json dual-scattering.json unreal-hair-strands.json)
set(hairlut_config_excludes PATTERN "generic.json" EXCLUDE)
foreach(cfg IN LISTS hairlut_unvalidated_configs)
  list(APPEND hairlut_config_excludes PATTERN "${cfg}" EXCLUDE)
  list(APPEND hairlut_unvalidated_files ${PROJECT_SOURCE_DIR}/tables/configs/${cfg})
endforeach()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/tables/configs/ DESTINATION ${CMAKE_INSTALL_DATADIR}/hairlut/tables/configs FILES_MATCHING PATTERN "*.json"
        ${hairlut_config_excludes})
install(FILES ${hairlut_unvalidated_files} DESTINATION ${CMAKE_INSTALL_DATADIR}/hairlut/tables/unvalidated-configs)
install(FILES ${PROJECT_SOURCE_DIR}/docs/unvalidated-configs.md DESTINATION ${CMAKE_INSTALL_DATADIR}/hairlut/tables/unvalidated-configs
        RENAME README.md)
install(FILES ${PROJECT_SOURCE_DIR}/tables/configs/generic.json DESTINATION ${CMAKE_INSTALL_DATADIR}/hairlut/bench)
# The GLSL runtime (an include for shaders; docs/gpu.md), beside the data it reads.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/lib/shaders/ DESTINATION ${CMAKE_INSTALL_DATADIR}/hairlut/shaders FILES_MATCHING PATTERN "*.glsl")
# The shipped default tables, which installed tools default to (bench-hair-luts).
install(FILES ${PROJECT_SOURCE_DIR}/tables/default/hairlut-default.h5 ${PROJECT_SOURCE_DIR}/tables/default/hairlut-default.json
        DESTINATION ${CMAKE_INSTALL_DATADIR}/hairlut/tables/default)
# The README and every document it links, laid out as in the repository so that its links work in
# share/doc/hairlut: docs/ (with the images and the bench output it shows), the example consumer.
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/CHANGELOG.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs
        FILES_MATCHING PATTERN "*.md" PATTERN "*.png" PATTERN "*.svg" PATTERN "*.csv" PATTERN "*.json" PATTERN "*.txt")
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)
