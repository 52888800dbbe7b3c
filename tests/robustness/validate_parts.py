#!/usr/bin/env python3
"""validate-hair-luts validates a set larger than its memory budget in parts, within the budget.

Usage: validate_parts.py BAKE VALIDATE WORKDIR

Bakes a generic set of about 113 MiB of N_p tables (no sampling data, as a slabbed bake writes
it), then validates it with --memory-budget 100 (MiB): the report must say it was read in parts
that tile the beta axis, judge the same checks as the whole set's validation, and the validator's
peak resident memory (getrusage of the child) must stay within the budget, below the set's own
size. The whole set's validation, for comparison, holds more than the set. A budget that cannot
hold one part is refused with exit 2 and one line that says what a part needs, as is a set with
sampling data for its N_p tables, which parts cannot split. A value planted in the file without
its checksum is refused in parts as it is whole.
"""
import json
import os
import shutil
import struct
import sys

import child_peak

BAKE, VALIDATE, WORK = sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3])
BUDGET_MIB = 100
failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL: " + msg)


shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
out = os.path.join(WORK, "set")
cfg = os.path.join(WORK, "big.json")
with open(cfg, "w") as f:
    json.dump({"name": "parts",
               "lobes": {"explicit": ["R", "TT", "TRT"], "residual": True},
               "tables": {"np": {"axes": {"theta_d": {"count": 96, "range_deg": [0, 85]}, "phi": {"count": 128},
                                          "sigma_a": {"count": 32, "range": [0, 4]},
                                          "beta": {"count": 24, "range_deg": [2, 20]}}}},
               "output": {"directory": out, "basename": "big", "formats": ["hdf5"], "sampling_data": False}}, f)
rc, _, err, _ = child_peak.peak_mib_of([BAKE, "--config", cfg, "--quiet", "--threads", "2"], WORK)
if rc != 0:
    print("FAIL: bake exit %d: %s" % (rc, err.strip()))
    sys.exit(1)
h5 = os.path.join(out, "big.h5")
set_mib = 3 * 24 * 32 * 96 * 128 * 4 / 2**20 + 0.1

common = ["--quiet", "--seed", "4", "--max-points", "4000", "--no-search", "--threads", "2"]
rc, _, err, parts_peak = child_peak.peak_mib_of([VALIDATE, h5, "--out", os.path.join(WORK, "parts"), "--memory-budget", str(BUDGET_MIB)] + common, WORK)
rc_whole, _, err_whole, whole_peak = child_peak.peak_mib_of([VALIDATE, h5, "--out", os.path.join(WORK, "whole")] + common, WORK)
print("set %.1f MiB; peak RSS in parts (budget %d MiB) %.1f MiB, whole %.1f MiB" % (set_mib, BUDGET_MIB, parts_peak, whole_peak))
if rc not in (0, 1) or rc_whole not in (0, 1):
    fail("validate exit %d (parts) and %d (whole): %s %s" % (rc, rc_whole, err.strip(), err_whole.strip()))
else:
    with open(os.path.join(WORK, "parts", "report.json")) as f:
        parts = json.load(f)
    with open(os.path.join(WORK, "whole", "report.json")) as f:
        whole = json.load(f)
    if "parts" not in parts or "parts" in whole:
        fail("only the run over budget should say it read the set in parts")
    else:
        p = parts["parts"]["parts"]
        print("%d parts: %s" % (len(p), ", ".join("%s (%.1f MiB)" % (x["beta_nodes"], x["bytes_held"] / 2**20) for x in p)))
        tiles = [x["beta_nodes"] for x in p]
        if len(p) < 2 or tiles[0][0] != 0 or tiles[-1][1] != 23 or any(a[1] != b[0] for a, b in zip(tiles, tiles[1:])):
            fail("the parts do not tile the beta nodes 0..23: %s" % tiles)
    if sorted(c["id"] for c in parts["checks"]) != sorted(c["id"] for c in whole["checks"]):
        fail("the checks differ: %s against %s" % ([c["id"] for c in parts["checks"]], [c["id"] for c in whole["checks"]]))
    if rc != rc_whole:
        fail("exit %d in parts, %d whole" % (rc, rc_whole))
    if parts_peak > BUDGET_MIB:
        fail("peak RSS in parts %.1f MiB is over the budget of %d MiB" % (parts_peak, BUDGET_MIB))
    if parts_peak > set_mib:
        fail("peak RSS in parts %.1f MiB is not below the set's %.1f MiB" % (parts_peak, set_mib))
    if whole_peak < set_mib:
        fail("the whole validation's peak %.1f MiB is below the set's %.1f MiB: the comparison says nothing" % (whole_peak, set_mib))

# A budget too small for one part: exit 2, one line naming the option and what a part needs.
rc, _, err, _ = child_peak.peak_mib_of([VALIDATE, h5, "--out", os.path.join(WORK, "small"), "--memory-budget", "70"] + common, WORK)
lines = err.strip().splitlines()
print("--memory-budget 70: exit %d, %s" % (rc, err.strip()))
if rc != 2 or len(lines) != 1 or "--memory-budget" not in lines[0] or "at least" not in lines[0]:
    fail("a budget that holds no part: exit %d, %r" % (rc, err))

# A set over the budget with stored sampling data for its N_p tables (which parts cannot split):
# refused before it is read through, in one line that says what validating it whole needs.
with_sampling = os.path.join(WORK, "sampling")
with open(cfg) as f:
    c = json.load(f)
c["output"]["directory"] = with_sampling
c["output"]["sampling_data"] = True
c["tables"]["np"]["axes"]["sigma_a"]["count"] = 16
sampling_cfg = os.path.join(WORK, "sampling.json")
with open(sampling_cfg, "w") as f:
    json.dump(c, f)
rc, _, err, _ = child_peak.peak_mib_of([BAKE, "--config", sampling_cfg, "--quiet", "--threads", "2"], WORK)
if rc != 0:
    fail("bake with sampling data exit %d: %s" % (rc, err.strip()))
else:
    rc, _, err, _ = child_peak.peak_mib_of([VALIDATE, os.path.join(with_sampling, "big.h5"), "--out", os.path.join(WORK, "s"), "--memory-budget", "64"] + common, WORK)
    print("sampling data, --memory-budget 64: exit %d, %s" % (rc, err.strip()))
    lines = err.strip().splitlines()
    if rc != 2 or len(lines) != 1 or "sampling data" not in lines[0] or "--memory-budget of" not in lines[0]:
        fail("a set with sampling data over the budget: exit %d, %r" % (rc, err))

# One float changed in the file (a value of np/TT, found by its bytes) with the checksum left as it
# was: refused in parts, as the whole load refuses it. The tables are stored compressed, so the
# edit goes into a copy baked uncompressed.
raw_cfg = os.path.join(WORK, "raw.json")
with open(cfg) as f:
    c = json.load(f)
c["output"]["directory"] = os.path.join(WORK, "raw")
c["output"]["hdf5"] = {"compression": 0}
with open(raw_cfg, "w") as f:
    json.dump(c, f)
rc, _, err, _ = child_peak.peak_mib_of([BAKE, "--config", raw_cfg, "--quiet", "--threads", "2"], WORK)
raw = os.path.join(WORK, "raw", "big.h5")
if rc != 0:
    fail("uncompressed bake exit %d: %s" % (rc, err.strip()))
else:
    os.remove(os.path.join(WORK, "raw", "big.json"))  # the sidecar's file hash would refuse it first
    with open(raw, "r+b") as f:
        data = f.read()
        at = len(data) // 2 // 4 * 4  # a value in the middle of the largest datasets
        (v,) = struct.unpack_from("<f", data, at)
        f.seek(at)
        f.write(struct.pack("<f", v * 1.5 + 1e-3))
    rc, _, err, _ = child_peak.peak_mib_of([VALIDATE, raw, "--out", os.path.join(WORK, "edited"), "--memory-budget", str(BUDGET_MIB)] + common, WORK)
    print("edited value, in parts: exit %d, %s" % (rc, err.strip()))
    if rc != 2 or "checksum" not in err:
        fail("an edited value was not refused by its checksum in parts: exit %d, %r" % (rc, err))

if failures:
    print("%d validate-parts check(s) failed" % len(failures))
    sys.exit(1)
print("all validate-parts checks passed")
