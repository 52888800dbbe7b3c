#!/usr/bin/env bash
# Interrupting bake-hair-luts (SIGINT, SIGTERM, SIGHUP) exits 128 + the signal (130, 143, 129)
# and leaves no partial file at the
# destination: an existing output stays byte-identical, and no temporary file remains.
set -euo pipefail
exe=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
make_config() {  # $1 = quadrature method
  cat > "$work/c.json" <<JSON
{ "name": "interrupt", "quadrature": { "method": "$1", "order": 64 },
  "tables": { "np": { "axes": {
    "theta_d": { "count": 24, "range_deg": [0, 85] }, "phi": { "count": 64 },
    "sigma_a": { "count": 6, "range": [0, 5] }, "beta": { "count": 6, "range_deg": [0.5, 30], "spacing": "log" } } } },
  "output": { "directory": "out", "basename": "t", "formats": ["hdf5", "exr"] } }
JSON
}
# A quick bake gives the existing output.
make_config gauss-legendre
"$exe" --config "$work/c.json" --quiet
before=$(cat "$work"/out/t.* | md5sum)
# A slow bake (adaptive reference) of a changed config, interrupted.
make_config adaptive
for sig in INT TERM HUP; do
  case $sig in INT) want=130;; TERM) want=143;; HUP) want=129;; esac
  "$exe" --config "$work/c.json" --quiet & pid=$!
  sleep 1.5
  kill -s $sig $pid
  set +e; wait $pid; rc=$?; set -e
  [ "$rc" -eq "$want" ] || { echo "SIG$sig: expected exit $want, got $rc"; exit 1; }
  after=$(cat "$work"/out/t.* | md5sum)
  [ "$before" = "$after" ] || { echo "SIG$sig: the existing output changed"; exit 1; }
  if ls "$work"/out | grep -q tmp; then echo "SIG$sig: temporary files left: $(ls "$work"/out)"; exit 1; fi
  echo "SIG$sig: exit $rc, output untouched, no temporaries"
done
