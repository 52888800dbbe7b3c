# The library's layers, bottom to top, and the rule that dependencies point down only. Each folder
# belongs to one link target (lib/CMakeLists.txt, docs/architecture.md), and a target links only the
# targets below it, so a call upwards already fails to link; this script is the fast check of the
# includes, which the link does not see (a header-only use of a higher layer, a declaration).
#
#   sampler  hairlut::runtime  header-only, dependency-free table sampler and renderer runtime (an engine copies it)
#   util     hairlut::physics  angles, errors, hashing, quadrature rules
#   physics  hairlut::physics  the scattering functions themselves
#   tables   hairlut::tables   grids, table sets and their typed views
#   io       hairlut::formats  HDF5, OpenEXR, engine textures, PNG, a table set's files and sidecar
#   bake     hairlut::bake     configs, the bakers, engine presets, the resolution planner, a config's outputs
#   report   hairlut::report   validation, comparison, reports, plots, benchmark pieces
#
# A table kind's folder, lib/kinds/<kind>/, a model's, lib/models/<model>/, and an engine preset's,
# lib/presets/<preset>/, span layers by file:
# <name>_<layer>.cpp belongs to that layer (bake or report; bake/table_kind.hpp, bake/model_kind.hpp)
# and may include that layer's private headers by folder ("bake/bake_internal.hpp"); a header there
# is private to the folder.
#
# Usage: cmake -DROOT=<a tree with lib/include/hairlut and lib/src> -P check_layers.cmake
# Every header and source of the library must sit in a layer folder (hairlut.hpp, the umbrella
# header, is the one exception); a file may include a hairlut header of its own layer or of a layer
# below, by its layer path ("hairlut/physics/fresnel.hpp"), and a private header of lib/src only
# from its own folder. The first violation of each file is reported with file and line; the script
# fails if there is any.
set(layers sampler util physics tables io bake report)
string(JOIN " < " layer_order ${layers})

if(NOT ROOT)
  message(FATAL_ERROR "usage: cmake -DROOT=<source tree> -P check_layers.cmake")
endif()
set(include_root ${ROOT}/lib/include/hairlut)
set(src_root ${ROOT}/lib/src)

set(violations "")
file(GLOB_RECURSE files RELATIVE ${ROOT}/lib ${include_root}/* ${src_root}/* ${ROOT}/lib/kinds/* ${ROOT}/lib/models/* ${ROOT}/lib/presets/*)
list(FILTER files INCLUDE REGEX "\\.(hpp|cpp|hpp\\.in)$")
if(NOT files)
  message(FATAL_ERROR "no library files under ${ROOT}/lib")
endif()
foreach(f IN LISTS files)
  if(f STREQUAL "include/hairlut/hairlut.hpp")
    continue()
  endif()
  set(folder_file FALSE)
  if(f MATCHES "^(kinds|models|presets)/([a-z][a-z0-9_]*)/([^/]+)$")
    set(folder_file TRUE)
    set(kind ${CMAKE_MATCH_2})
    set(name ${CMAKE_MATCH_3})
    if(name MATCHES "\\.hpp$")
      set(layer report)  # a folder's private header: its includes are checked against the highest layer
    elseif(name MATCHES "^${kind}_(bake|report)\\.cpp$")
      set(layer ${CMAKE_MATCH_1})
    else()
      list(APPEND violations "lib/${f}: a kind's, model's or preset's source is <name>_bake.cpp or <name>_report.cpp")
      continue()
    endif()
  elseif(NOT f MATCHES "^(include/hairlut|src)/([a-z_]+)/[^/]+$")
    list(APPEND violations "lib/${f}: not in a layer folder (${layer_order})")
    continue()
  else()
    set(layer ${CMAKE_MATCH_2})
  endif()
  list(FIND layers ${layer} rank)
  if(rank EQUAL -1)
    list(APPEND violations "lib/${f}: '${layer}' is not a layer (${layer_order})")
    continue()
  endif()
  get_filename_component(dir ${ROOT}/lib/${f} DIRECTORY)
  file(STRINGS ${ROOT}/lib/${f} lines REGEX "^[ \t]*#[ \t]*include[ \t]*[\"<]")
  foreach(line IN LISTS lines)
    if(line MATCHES "[\"<]hairlut/([^\">]+)[\">]")
      set(target ${CMAKE_MATCH_1})
      if(NOT target MATCHES "^([a-z_]+)/[^/]+\\.hpp$")
        list(APPEND violations "lib/${f}: includes hairlut/${target}, not a layer header")
        continue()
      endif()
      list(FIND layers ${CMAKE_MATCH_1} target_rank)
      if(target_rank EQUAL -1)
        list(APPEND violations "lib/${f}: includes hairlut/${target}: '${CMAKE_MATCH_1}' is not a layer")
      elseif(target_rank GREATER rank)
        list(APPEND violations "lib/${f}: ${layer}/ includes hairlut/${target}, a higher layer")
      endif()
    elseif(line MATCHES "\"([^\"/]+\\.hpp)\"")
      # A private header of lib/src: must sit beside the file that includes it.
      if(NOT EXISTS ${dir}/${CMAKE_MATCH_1})
        list(APPEND violations "lib/${f}: includes \"${CMAKE_MATCH_1}\", which is not in its own folder")
      endif()
    elseif(folder_file AND line MATCHES "\"([a-z_]+)/([^\"/]+\\.hpp)\"")
      # A kind's or model's file including its own layer's private header by folder.
      if(NOT CMAKE_MATCH_1 STREQUAL layer OR NOT EXISTS ${src_root}/${CMAKE_MATCH_1}/${CMAKE_MATCH_2})
        list(APPEND violations "lib/${f}: includes \"${CMAKE_MATCH_1}/${CMAKE_MATCH_2}\", not a private header of its own layer (${layer})")
      endif()
    elseif(line MATCHES "\"")
      list(APPEND violations "lib/${f}: unexpected include: ${line}")
    endif()
  endforeach()
endforeach()

if(violations)
  list(LENGTH violations n)
  string(REPLACE ";" "\n  " text "${violations}")
  message(FATAL_ERROR "${n} layering violation(s):\n  ${text}")
endif()
list(LENGTH files n)
message(STATUS "${n} library files, every include points to its own layer or one below (${layer_order})")
