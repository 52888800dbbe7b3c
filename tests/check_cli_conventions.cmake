# The conventions every tool shares (tools/common/cli.hpp, README "Command-line tools"), checked
# across all of them in one place so that they cannot drift apart:
#   --version             exit 0, "<tool> (hairlut) VERSION" on stdout, nothing on stderr;
#   an unknown option     exit 2, exactly "<tool>: error: unknown option or argument: <it> (see --help)";
#   a missing input file  exit 2, one line "<tool>: error: ..." naming the file (hairlut-eval reads
#                         no file and has no such case);
#   an unwritable --out   validate-hair-luts exits 1 before it validates anything.
# BAKE, VALIDATE, EVAL, COMPARE, BENCH and RENDER are the binaries, VERSION the project version,
# WORK a scratch directory and TABLE a table file that validates.
set(failures "")
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

# Runs EXE with the remaining arguments; sets rc, out and err in the caller.
function(run_tool exe)
  execute_process(COMMAND ${exe} ${ARGN} RESULT_VARIABLE r OUTPUT_VARIABLE o ERROR_VARIABLE e TIMEOUT 60)
  set(rc "${r}" PARENT_SCOPE)
  set(out "${o}" PARENT_SCOPE)
  set(err "${e}" PARENT_SCOPE)
endfunction()

# Checks an error run: exit status code, nothing on stdout, one stderr line matching regex.
function(expect what code regex)
  string(REGEX MATCHALL "\n" newlines "${err}")
  list(LENGTH newlines n)
  if(NOT rc STREQUAL "${code}")
    string(APPEND failures "${what}: exit ${rc}, expected ${code}; stderr: ${err}\n")
  elseif(NOT n EQUAL 1)
    string(APPEND failures "${what}: ${n} lines on stderr, expected 1:\n${err}")
  elseif(NOT err MATCHES "${regex}")
    string(APPEND failures "${what}: stderr does not match '${regex}':\n${err}")
  elseif(NOT out STREQUAL "")
    string(APPEND failures "${what}: wrote to stdout:\n${out}")
  else()
    message(STATUS "${what} -> ${rc}: ${err}")
  endif()
  set(failures "${failures}" PARENT_SCOPE)
endfunction()

set(missing_json ${WORK}/missing.json)
set(missing_h5 ${WORK}/missing.h5)
foreach(tool bake-hair-luts validate-hair-luts hairlut-eval compare-hair-models bench-hair-luts render-hair-luts)
  if(tool STREQUAL "bake-hair-luts")
    set(exe ${BAKE})
    set(missing_input --config ${missing_json} --check)
  elseif(tool STREQUAL "validate-hair-luts")
    set(exe ${VALIDATE})
    set(missing_input ${missing_h5} --quiet --out ${WORK}/validate)
  elseif(tool STREQUAL "hairlut-eval")
    set(exe ${EVAL})
    set(missing_input "")
  elseif(tool STREQUAL "compare-hair-models")
    set(exe ${COMPARE})
    set(missing_input --config ${missing_json} --quiet --no-energy --out ${WORK}/compare)
  elseif(tool STREQUAL "bench-hair-luts")
    set(exe ${BENCH})
    set(missing_input --generic-config ${missing_json} --quick --quiet --out ${WORK}/bench)
  elseif(tool STREQUAL "render-hair-luts")
    set(exe ${RENDER})
    set(missing_input --tables ${missing_h5} --output-dir ${WORK}/render)
  endif()

  run_tool(${exe} --version)
  if(NOT rc STREQUAL "0" OR NOT out MATCHES "^${tool} \\(hairlut\\) ${VERSION}\n$" OR NOT err STREQUAL "")
    string(APPEND failures "${tool} --version: exit ${rc}, stdout '${out}', stderr '${err}'\n")
  else()
    message(STATUS "${tool} --version -> 0: ${out}")
  endif()

  run_tool(${exe} --no-such-flag)
  expect("${tool} --no-such-flag" 2 "^${tool}: error: unknown option or argument: --no-such-flag \\(see --help\\)\n$")

  if(missing_input)
    run_tool(${exe} ${missing_input})
    expect("${tool} with a missing input file" 2 "^${tool}: error: [^\n]*missing\\.(json|h5)")
  endif()
endforeach()

# validate-hair-luts refuses an --out it cannot write into before the work (the default tables take
# a minute to validate; the refusal must come at once).
file(WRITE ${WORK}/a-file "")
string(TIMESTAMP start "%s")
run_tool(${VALIDATE} ${TABLE} --quiet --out ${WORK}/a-file/report)
string(TIMESTAMP end "%s")
math(EXPR seconds "${end} - ${start}")
expect("validate-hair-luts with --out under a regular file" 1 "^validate-hair-luts: error: --out [^\n]*a-file/report")
if(seconds GREATER 10)
  string(APPEND failures "validate-hair-luts took ${seconds} s to refuse an unwritable --out (not before the work)\n")
endif()

if(failures)
  message(FATAL_ERROR "${failures}")
endif()
