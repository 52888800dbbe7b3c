#!/usr/bin/env bash
# Installs missing Debian packages, configures (CMake preset "release") and builds hairlut.
# Idempotent and incremental: a second run only rebuilds what changed.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup-debian.sh
if [ ! -f build/release/CMakeCache.txt ]; then
  cmake --preset release
fi
cmake --build --preset release -j "$(nproc)"
