# Runs one libFuzzer binary for SECONDS over a copy of CORPUS; fails on any crash or sanitizer
# report (libFuzzer's exit code) and prints where the crashing input was saved.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}/corpus" "${WORK}/artifacts")
file(GLOB seeds "${CORPUS}/*")
file(COPY ${seeds} DESTINATION "${WORK}/corpus")
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env "ASAN_OPTIONS=${ASAN}" ${EXE} -max_total_time=${SECONDS} -rss_limit_mb=3072 -timeout=20 -max_len=262144 -print_final_stats=1 ${EXTRA}
          -artifact_prefix=${WORK}/artifacts/ ${WORK}/corpus
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX MATCH "stat::number_of_executed_units: *[0-9]+" runs "${err}")
if(NOT rc EQUAL 0)
  string(LENGTH "${err}" len)
  if(len GREATER 6000)
    math(EXPR start "${len} - 6000")
    string(SUBSTRING "${err}" ${start} 6000 err)
  endif()
  message(FATAL_ERROR "fuzzer failed (exit ${rc}); artifacts in ${WORK}/artifacts\n${err}")
endif()
message(STATUS "no crash: ${runs}")
