#!/usr/bin/env python3
"""Loading and validating a table set hold it once, not twice.

Usage: load_memory.py BAKE VALIDATE PYTHONPATH WORKDIR

Bakes a small set (a few MiB) and a large one (about 100 MiB of tables and sampling data, the
N_p tables with their stored sampling data), then measures the peak resident memory (getrusage
of the child) of validate-hair-luts and of the Python module's load_tables on each. What the large
set adds to the peak over the small one must stay within 1.15 times what its tables add: the
values read once, plus HDF5's chunk cache and the report. Before, the validator recomputed each
table's sampling data whole beside it (eight times a table's values in Bernstein form), and
load_tables copied every table into numpy: both about twice the set.
"""
import json
import os
import shutil
import sys

import child_peak

BAKE, VALIDATE, PYTHONPATH, WORK = sys.argv[1], sys.argv[2], sys.argv[3], os.path.abspath(sys.argv[4])
ALLOWANCE = 1.15
failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL: " + msg)


def config(directory, beta_count):
    return {
        "name": "load-memory",
        "lobes": {"explicit": ["R", "TT", "TRT"], "residual": True},
        "quadrature": {"method": "fourier", "tolerance": 1e-6},
        "tables": {"np": {"normalize": "energy",
                          "axes": {"theta_d": {"count": 48, "range_deg": [0, 85]}, "phi": {"count": 128, "symmetry": "even"},
                                   "sigma_a": {"count": 12, "range": [0, 8], "spacing": "sqrt"},
                                   "beta": {"count": beta_count, "range_deg": [3, 30], "spacing": "log"}}}},
        "output": {"directory": directory, "basename": "t", "formats": ["hdf5"]},
    }


def measure(label, beta_count):
    out = os.path.join(WORK, label)
    cfg = os.path.join(WORK, label + ".json")
    with open(cfg, "w") as f:
        json.dump(config(out, beta_count), f)
    rc, _, err, _ = child_peak.peak_mib_of([BAKE, "--config", cfg, "--quiet", "--force", "--threads", "2"], WORK)
    if rc != 0:
        fail("%s: bake exit %d: %s" % (label, rc, err.strip()))
        return None
    h5 = os.path.join(out, "t.h5")
    # The tables' bytes as loaded, from the module itself.
    script = ("import sys; sys.path.insert(0, %r); import hairlut._core as c; "
              "s = c.load_tables(%r); print(sum(t['values'].nbytes for t in s['tables']))") % (PYTHONPATH, h5)
    rc, stdout, err, py_peak = child_peak.peak_mib_of([sys.executable, "-c", script], WORK)
    if rc != 0:
        fail("%s: load_tables exit %d: %s" % (label, rc, err.strip()))
        return None
    tables = int(stdout.split()[-1]) / 1048576.0
    rc, _, err, val_peak = child_peak.peak_mib_of([VALIDATE, h5, "--out", os.path.join(WORK, label + "-report"), "--quiet", "--no-search",
                                                   "--max-points", "200", "--seed", "1", "--threads", "2"], WORK)
    if rc not in (0, 1):  # 1: a check failed (these coarse tables miss the default thresholds); the run completed
        fail("%s: validate exit %d: %s" % (label, rc, err.strip()))
        return None
    print("%s: tables %.1f MiB; peak of load_tables %.1f MiB, of validate-hair-luts %.1f MiB" % (label, tables, py_peak, val_peak), flush=True)
    return tables, py_peak, val_peak


def main():
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    small, large = measure("small", 2), measure("large", 32)
    if small and large:
        added = large[0] - small[0]
        for i, tool in ((1, "load_tables"), (2, "validate-hair-luts")):
            grew = large[i] - small[i]
            print("%s: %.1f MiB more for %.1f MiB more tables (%.2f times)" % (tool, grew, added, grew / added))
            if grew > ALLOWANCE * added:
                fail("%s holds %.2f times the tables it loads (at most %.2f)" % (tool, grew / added, ALLOWANCE))
    if failures:
        print("%d load-memory check(s) failed" % len(failures))
        sys.exit(1)
    print("all load-memory checks passed")


main()
