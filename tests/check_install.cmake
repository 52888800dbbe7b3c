# Installs the build tree BUILD into a fresh prefix under WORK, then uses the installed package as
# a stranger would: checks the installed files and that the documents the README links are there,
# runs an installed tool and checks that the tools default to installed data, configures and builds the
# consumer project SOURCE/examples/engine-consumer with find_package(hairlut CONFIG) against that
# prefix only, runs it on TABLE, checks the package version rule, the runtime-only component (and
# its earlier name, sampler) and a consumer of one compiled layer (physics),
# compiles the consumer once more with the installed pkg-config file's flags (plain and --static),
# and imports the installed Python module with PYTHON when it was built.
# VERSION is the project version; CXX the C++ compiler; CONFIG the build configuration.
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(run_out "${out}" PARENT_SCOPE)
endfunction()

set(prefix ${WORK}/prefix)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
run("cmake --install" ${CMAKE_COMMAND} --install ${BUILD} --prefix ${prefix} --config ${CONFIG})

# The installed files.
file(GLOB libs ${prefix}/lib*/libhairlut_physics.a)
if(NOT libs)
  message(FATAL_ERROR "no libhairlut_physics.a installed under ${prefix}/lib*")
endif()
list(GET libs 0 lib)
get_filename_component(libdir ${lib} DIRECTORY)
foreach(layer tables formats bake report)
  if(NOT EXISTS ${libdir}/libhairlut_${layer}.a)
    message(FATAL_ERROR "not installed: ${libdir}/libhairlut_${layer}.a")
  endif()
endforeach()
foreach(f include/hairlut/sampler/sampler.hpp include/hairlut/sampler/hair_scattering.hpp include/hairlut/tables/tables.hpp include/hairlut/util/version.hpp
          share/hairlut/schemas/hairlut-config.schema.json share/hairlut/schemas/hairlut-tables.schema.json
          share/hairlut/tables/configs/default.json share/hairlut/tables/default/hairlut-default.h5 share/doc/hairlut/LICENSE
          share/hairlut/shaders/hairlut.glsl
          bin/bake-hair-luts bin/validate-hair-luts bin/hairlut-eval bin/compare-hair-models bin/bench-hair-luts bin/render-hair-luts bin/export-hair-luts)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
foreach(f cmake/hairlut/hairlutConfig.cmake cmake/hairlut/hairlutConfigVersion.cmake cmake/hairlut/hairlut-targets.cmake
          cmake/hairlut/hairlut-runtime-targets.cmake pkgconfig/hairlut.pc)
  if(NOT EXISTS ${libdir}/${f})
    message(FATAL_ERROR "not installed: ${libdir}/${f}")
  endif()
endforeach()
run("installed bake-hair-luts --version" ${prefix}/bin/bake-hair-luts --version)
if(NOT run_out MATCHES "bake-hair-luts \\(hairlut\\) ${VERSION}")
  message(FATAL_ERROR "installed bake-hair-luts --version printed: ${run_out}")
endif()

# The documents the README links are installed beside it, laid out as in the repository, so its
# links to documents (*.md) and to the example work in share/doc/hairlut.
set(docdir ${prefix}/share/doc/hairlut)
foreach(doc README.md docs/performance.md docs/baking.md)
  if(NOT EXISTS ${docdir}/${doc})
    message(FATAL_ERROR "not installed: share/doc/hairlut/${doc}")
  endif()
endforeach()
file(GLOB_RECURSE installed_docs ${docdir}/*.md)
foreach(doc IN LISTS installed_docs)
  file(READ ${doc} text)
  get_filename_component(here ${doc} DIRECTORY)
  # Brackets would split CMake's lists: the link targets are found after "](" replaced by a marker.
  string(REPLACE "](" "\nLINK:" text "${text}")
  string(REPLACE "[" "(" text "${text}")
  string(REPLACE "]" ")" text "${text}")
  string(REGEX MATCHALL "LINK:[^)#; \n]+" targets "${text}")
  foreach(target IN LISTS targets)
    string(REGEX REPLACE "^LINK:" "" target "${target}")
    # Documents, images and the example; links to the sources (tools/*.cpp) point into a checkout.
    if(target MATCHES "^[a-z]+:" OR NOT target MATCHES "(\\.md|\\.png|\\.svg)$|examples/")
      continue()
    endif()
    if(NOT EXISTS ${here}/${target})
      message(FATAL_ERROR "${doc} links ${target}, which is not installed")
    endif()
  endforeach()
endforeach()

# Installed tools default to installed data: bench-hair-luts' defaults name the prefix, not the sources
# (its generic.json, a benchmark input, apart from the configs).
run("installed bench-hair-luts --help" ${prefix}/bin/bench-hair-luts --help)
foreach(default "${prefix}/share/hairlut/bench/generic.json" "${prefix}/bin/bake-hair-luts")
  string(FIND "${run_out}" "${default}" at)
  if(at LESS 0)
    message(FATAL_ERROR "installed bench-hair-luts does not default to ${default}:\n${run_out}")
  endif()
endforeach()
string(FIND "${run_out}" "${SOURCE}/tables" at)
if(NOT at LESS 0)
  message(FATAL_ERROR "installed bench-hair-luts defaults to the source tree's ${SOURCE}/tables:\n${run_out}")
endif()

# The consumer, found through the prefix alone (no package registry, no build tree).
set(consumer ${WORK}/consumer)
run("configuring the consumer" ${CMAKE_COMMAND} -S ${SOURCE}/examples/engine-consumer -B ${consumer} -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
file(STRINGS ${consumer}/CMakeCache.txt hairlut_dir REGEX "^hairlut_DIR:")
string(FIND "${hairlut_dir}" "${prefix}/" at)
if(NOT at GREATER -1)
  message(FATAL_ERROR "the consumer found hairlut outside the prefix: ${hairlut_dir}")
endif()
run("building the consumer" ${CMAKE_COMMAND} --build ${consumer} --verbose)
# OpenMP is private: no consumer source file is compiled with -fopenmp.
string(REGEX MATCHALL "[^\n]*-c [^\n]*sample_table.cpp[^\n]*" compile_lines "${run_out}")
if(NOT compile_lines)
  message(FATAL_ERROR "no compile line of sample_table.cpp in the verbose build output:\n${run_out}")
endif()
if(compile_lines MATCHES "-fopenmp")
  message(FATAL_ERROR "the consumer is compiled with OpenMP flags:\n${compile_lines}")
endif()
run("sample-table" ${consumer}/sample-table ${TABLE} TRT 20 0.5 5 30)
if(NOT run_out MATCHES "np/TRT\\(theta_d=20 deg, sigma_a=0.5, beta=5 deg, phi=30 deg\\) = [0-9.e+-]+ 1/rad")
  message(FATAL_ERROR "unexpected sample-table output: ${run_out}")
endif()
message(STATUS "${run_out}")
# The README's load-and-sample program.
run("load-and-sample" ${consumer}/load-and-sample ${TABLE})
if(NOT run_out MATCHES "weight [0-9.]+ [0-9.]+ [0-9.]+ = S / pdf")
  message(FATAL_ERROR "unexpected load-and-sample output: ${run_out}")
endif()
message(STATUS "${run_out}")
run("furnace" ${consumer}/furnace ${TABLE} 0 0 10 10 2000)
if(NOT run_out MATCHES "theta_o +albedo")
  message(FATAL_ERROR "unexpected furnace output: ${run_out}")
endif()
message(STATUS "${run_out}")
run("sampler-only" ${consumer}/sampler-only)
message(STATUS "${run_out}")

# Version rule and the dependency-free runtime component, also under its earlier name.
file(WRITE ${WORK}/package-check/CMakeLists.txt "cmake_minimum_required(VERSION 3.22)
project(package_check LANGUAGES NONE)
find_package(hairlut 99.0 CONFIG QUIET)
if(hairlut_FOUND)
  message(FATAL_ERROR \"a request for hairlut 99.0 accepted version \${hairlut_VERSION}\")
endif()
find_package(hairlut ${VERSION} CONFIG REQUIRED COMPONENTS runtime)
if(NOT TARGET hairlut::runtime OR TARGET hairlut::physics OR TARGET hairlut::hairlut OR nlohmann_json_DIR)
  message(FATAL_ERROR \"COMPONENTS runtime must give hairlut::runtime alone, without dependencies\")
endif()
get_target_property(features hairlut::runtime INTERFACE_COMPILE_FEATURES)
get_target_property(links hairlut::runtime INTERFACE_LINK_LIBRARIES)
if(NOT features STREQUAL \"cxx_std_17\" OR links)
  message(FATAL_ERROR \"hairlut::runtime: features \${features}, links \${links}\")
endif()
find_package(hairlut ${VERSION} CONFIG REQUIRED COMPONENTS sampler)
get_target_property(aliased hairlut::sampler ALIASED_TARGET)
if(NOT aliased STREQUAL \"hairlut::runtime\" OR TARGET hairlut::hairlut)
  message(FATAL_ERROR \"COMPONENTS sampler must give hairlut::sampler, an alias of hairlut::runtime (got \${aliased})\")
endif()
")
run("the package version and runtime component check" ${CMAKE_COMMAND} -S ${WORK}/package-check -B ${WORK}/package-check/build
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)

# One compiled layer alone: a consumer of hairlut::physics builds and runs without HDF5, OpenEXR
# and zlib, which the package then does not look up.
file(WRITE ${WORK}/physics-only/CMakeLists.txt "cmake_minimum_required(VERSION 3.22)
project(physics_only LANGUAGES CXX)
find_package(hairlut ${VERSION} CONFIG REQUIRED COMPONENTS physics)
if(DEFINED HDF5_FOUND OR DEFINED OpenEXR_DIR OR DEFINED ZLIB_FOUND)
  message(FATAL_ERROR \"COMPONENTS physics looked up a file format library\")
endif()
add_executable(physics-only physics_only.cpp)
target_link_libraries(physics-only PRIVATE hairlut::physics)
")
file(WRITE ${WORK}/physics-only/physics_only.cpp "#include <cstdio>
#include <hairlut/physics/longitudinal_mp.hpp>
int main() {
  const double m = hairlut::longitudinal_deon(0.01, 0.5, -0.5);  // d'Eon's M_p, variance 0.01, theta_i 0.5, theta_r -0.5
  std::printf(\"M_p %.6f\\n\", m);
  return m > 0.0 ? 0 : 1;
}
")
run("configuring the physics-only consumer" ${CMAKE_COMMAND} -S ${WORK}/physics-only -B ${WORK}/physics-only/build -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
run("building the physics-only consumer" ${CMAKE_COMMAND} --build ${WORK}/physics-only/build)
run("physics-only" ${WORK}/physics-only/build/physics-only)
message(STATUS "physics-only: ${run_out}")

# pkg-config: the same consumer built with the installed hairlut.pc's flags. The README's line,
# `c++ -std=c++20 prog.cpp $(pkg-config --cflags --libs hairlut)`, has no --static: the installed
# library is static, so the plain --libs must already name everything it links against. Compiled
# once (--cflags) and linked with the plain --libs, which is what that line does, and with
# --static --libs, which must link too.
find_program(PKG_CONFIG pkg-config REQUIRED)
set(ENV{PKG_CONFIG_PATH} ${libdir}/pkgconfig)
run("pkg-config --cflags" ${PKG_CONFIG} --cflags hairlut)
string(STRIP "${run_out}" flags)
separate_arguments(flags UNIX_COMMAND "${flags}")
run("compiling with `pkg-config --cflags hairlut`" ${CXX} -std=c++20 -O1 -c ${SOURCE}/examples/engine-consumer/load_and_sample.cpp ${flags}
    -o ${WORK}/pc-sample-table.o)
foreach(mode plain static)
  if(mode STREQUAL "plain")
    run("pkg-config --libs" ${PKG_CONFIG} --libs hairlut)
  else()
    run("pkg-config --static --libs" ${PKG_CONFIG} --static --libs hairlut)
  endif()
  string(STRIP "${run_out}" libs)
  separate_arguments(libs UNIX_COMMAND "${libs}")
  run("linking with pkg-config's ${mode} --libs (${libs})" ${CXX} ${WORK}/pc-sample-table.o ${libs} -o ${WORK}/pc-sample-table-${mode})
  run("the pkg-config build (${mode} --libs)" ${WORK}/pc-sample-table-${mode} ${TABLE})
  if(NOT run_out MATCHES "= S / pdf")
    message(FATAL_ERROR "the pkg-config build (${mode} --libs) printed: ${run_out}")
  endif()
  message(STATUS "${mode}: ${run_out}")
endforeach()

# The Python module, when it was built: importable from the prefix.
file(GLOB_RECURSE python_init ${prefix}/__init__.py)
list(FILTER python_init INCLUDE REGEX "/hairlut/__init__.py$")
if(python_init AND PYTHON)
  list(GET python_init 0 init)
  get_filename_component(package_dir ${init} DIRECTORY)
  get_filename_component(site_dir ${package_dir} DIRECTORY)
  set(ENV{PYTHONPATH} ${site_dir})
  run("importing the installed Python module" ${PYTHON} -c "import hairlut as h
print(h.__file__, h.__version__)")
  if(NOT run_out MATCHES "^${site_dir}/hairlut/__init__.py ${VERSION}")
    message(FATAL_ERROR "the installed Python module: ${run_out}")
  endif()
  message(STATUS "Python module: ${run_out}")
endif()
