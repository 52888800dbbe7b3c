#!/usr/bin/env bash
# Runs every hairlut test (building first as needed). Extra arguments go to ctest, e.g. -R furnace.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
ctest --preset release -j "$(nproc)" "$@"
