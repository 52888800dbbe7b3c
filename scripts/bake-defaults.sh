#!/usr/bin/env bash
# Builds hairlut (installing dependencies as needed) and bakes the default tables into
# tables/default/. Extra arguments go to the baker (e.g. --force, --quiet).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
mkdir -p tables/default
# Until bake-hair-luts exists (issue 3), record the white-furnace energies of the default model.
build/release/tools/hairlut-eval/hairlut-eval --json furnace --beta-deg 10 --lobes 3 --residual \
  --theta-i-deg -89,-75,-60,-45,-30,-15,0,15,30,45,60,75,89 > tables/default/furnace.json.tmp
mv tables/default/furnace.json.tmp tables/default/furnace.json
echo "wrote tables/default/furnace.json"
