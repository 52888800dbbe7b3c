# The baker loads OpenEXR only for configs that ask for EXR files: a bake of HDF5 files alone must
# not map the module hairlut-exr.so nor any OpenEXR library, and a bake that writes an EXR file must
# (the control, which shows that the dynamic loader's trace below sees a module loaded by dlopen).
# The loader's own trace (LD_DEBUG=files) lists every shared object the process maps, including
# those loaded with dlopen. (Imath, the half-float library OpenEXR builds on, is not OpenEXR: the
# library's own half rounding of checksums uses it.) Usage: cmake -DBAKE=<bake-hair-luts> -DWORK=<scratch dir> -P this file.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

# A small per-material config (one material, few nodes); FORMATS is the output.formats list.
function(write_config path formats)
  file(WRITE "${path}" "{
  \"name\": \"exr-on-demand\",
  \"model\": \"deon2011\",
  \"lobes\": {\"explicit\": [\"R\", \"TT\", \"TRT\"], \"residual\": false},
  \"tables\": {\"np\": {\"axes\": {\"theta_d\": {\"count\": 4, \"range_deg\": [0, 90]}, \"phi\": {\"count\": 8}}}},
  \"scene\": {\"mode\": \"per-material\", \"materials\": [{\"name\": \"m0\", \"melanin\": {\"eumelanin\": 0.3, \"pheomelanin\": 0.1}, \"beta_deg\": {\"R\": 5, \"TT\": 5, \"TRT\": 5}}]},
  \"output\": {\"directory\": \".\", \"basename\": \"exr-on-demand\", \"formats\": ${formats}}
}
")
endfunction()

# Writes a config with output.formats FORMATS under WORK/NAME.json, bakes it into WORK/NAME with the
# loader's trace, checks that the baker wrote WORK/NAME/exr-on-demand.EXPECTED, and sets TRACE in
# the caller to the trace.
function(bake_traced name formats expected)
  set(config "${WORK}/${name}.json")
  set(out_dir "${WORK}/${name}")
  write_config("${config}" "${formats}")
  execute_process(COMMAND ${CMAKE_COMMAND} -E env LD_DEBUG=files "${BAKE}" --config "${config}" --output-dir "${out_dir}" --force --quiet
                  --threads 1 RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "bake of ${config} failed (exit ${rc}):\n${out}\n${err}")
  endif()
  if(NOT EXISTS "${out_dir}/exr-on-demand.${expected}")
    message(FATAL_ERROR "the bake of ${name}.json wrote no ${expected} file")
  endif()
  set(TRACE "${out}\n${err}" PARENT_SCOPE)
endfunction()

bake_traced(hdf5-only "[\"hdf5\"]" h5)
# The trace must be there at all (it names the C library the baker always maps).
if(NOT TRACE MATCHES "file=[^\n]*libc\\.so")
  message(FATAL_ERROR "LD_DEBUG=files gave no loader trace; cannot check which libraries the baker maps:\n${TRACE}")
endif()
string(REGEX MATCHALL "file=[^\n]*(hairlut-exr|OpenEXR|libIex|libIlmThread)[^\n]*" loaded "${TRACE}")
if(loaded)
  list(JOIN loaded "\n" shown)
  message(FATAL_ERROR "an HDF5-only bake mapped OpenEXR code:\n${shown}")
endif()

bake_traced(with-exr "[\"hdf5\", \"exr\"]" exr)
if(NOT TRACE MATCHES "file=[^\n]*hairlut-exr\\.so[^\n]*dynamically loaded")
  message(FATAL_ERROR "the bake with EXR output shows no dlopen of hairlut-exr.so in the loader's trace:\n${TRACE}")
endif()
message(STATUS "OpenEXR loaded on demand only")
