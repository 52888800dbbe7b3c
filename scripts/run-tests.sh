#!/usr/bin/env bash
# Runs every hairlut test, building first as needed: the Catch2, command-line and Python tests of
# the release build, then the libFuzzer targets (clang, AddressSanitizer + UBSan) for a bounded
# time each (HAIRLUT_FUZZ_SECONDS, default 15) and the robustness probes against bake-hair-luts and
# validate-hair-luts built with the same sanitizers. Extra arguments go to the first ctest, e.g. -R furnace.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
# One job more than cores: a few tests mostly wait (signals, interrupts, the install check's cmake).
ctest --preset release -j "$(( $(nproc) + 1 ))" "$@"
if [ $# -eq 0 ]; then
  if [ ! -f build/fuzz/CMakeCache.txt ]; then cmake --preset fuzz; fi
  cmake -DHAIRLUT_FUZZ_SECONDS="${HAIRLUT_FUZZ_SECONDS:-15}" -DHAIRLUT_BUILD_TOOLS=ON build/fuzz > /dev/null
  cmake --build --preset fuzz -j "$(nproc)"
  ctest --preset fuzz -j "$(nproc)"
fi
