#!/usr/bin/env bash
# Builds hairlut (installing dependencies as needed) and bakes the default tables of
# tables/configs/default.json into tables/default/. Extra arguments go to bake-hair-luts
# (e.g. --force, --quiet, --threads N). An up-to-date output is left alone.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
build/release/tools/bake-hair-luts/bake-hair-luts --config tables/configs/default.json "$@"
