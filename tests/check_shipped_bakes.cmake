# No-behaviour-change guard: shipped configs bake exactly the bytes recorded in MANIFEST.
#
# This is not an accuracy test (the physics and tables are tested against independent references
# elsewhere): it pins the output of a code move or refactor to the output before it, file by file,
# byte for byte. A deliberate change of values or format re-records the manifest in the same commit,
# saying why:  cmake -DRECORD=ON -DBAKE=... -DSOURCE=... -DWORK=... -DMANIFEST=... -P this file
#
# BAKE: bake-hair-luts; SOURCE: the source tree; WORK: a scratch folder; MANIFEST: lines
# "<config> <file> <sha256>"; CONFIGS: ;-list of names under tables/configs/ (default: all).
foreach(v BAKE SOURCE WORK MANIFEST)
  if(NOT ${v})
    message(FATAL_ERROR "check_shipped_bakes.cmake: ${v} is not set")
  endif()
endforeach()
if(NOT CONFIGS)
  file(GLOB paths ${SOURCE}/tables/configs/*.json)
  foreach(p IN LISTS paths)
    get_filename_component(n ${p} NAME_WE)
    list(APPEND CONFIGS ${n})
  endforeach()
endif()

set(recorded "")
if(NOT RECORD)
  file(STRINGS ${MANIFEST} lines REGEX "^[a-z]")
  foreach(line IN LISTS lines)
    string(REPLACE " " ";" fields "${line}")
    list(GET fields 0 c)
    list(GET fields 1 f)
    list(GET fields 2 h)
    set(expected_${c}_${f} ${h})
    list(APPEND recorded_${c} ${f})
  endforeach()
endif()

set(failures "")
set(out "")
foreach(c IN LISTS CONFIGS)
  set(dir ${WORK}/${c})
  file(REMOVE_RECURSE ${dir})
  execute_process(COMMAND ${BAKE} --config ${SOURCE}/tables/configs/${c}.json --output-dir ${dir} --force --quiet
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "baking tables/configs/${c}.json failed (${rc}): ${err}")
  endif()
  file(GLOB produced RELATIVE ${dir} ${dir}/*)
  list(SORT produced)
  if(NOT RECORD AND NOT "${produced}" STREQUAL "${recorded_${c}}")
    list(APPEND failures "${c}: files ${produced}, recorded ${recorded_${c}}")
  endif()
  foreach(f IN LISTS produced)
    file(SHA256 ${dir}/${f} h)
    string(APPEND out "${c} ${f} ${h}\n")
    if(NOT RECORD AND NOT h STREQUAL "${expected_${c}_${f}}")
      list(APPEND failures "${c}/${f}: sha256 ${h}, recorded ${expected_${c}_${f}}")
    endif()
  endforeach()
endforeach()

if(RECORD)
  file(WRITE ${MANIFEST} "# Shipped configs' baked bytes: config, file, sha256 (tests/check_shipped_bakes.cmake).\n${out}")
  message(STATUS "recorded ${MANIFEST}")
elseif(failures)
  string(REPLACE ";" "\n  " text "${failures}")
  message(FATAL_ERROR "baked bytes differ from the recorded ones:\n  ${text}")
else()
  list(JOIN CONFIGS ", " names)
  message(STATUS "byte-identical to the record: ${names}")
endif()
