#!/usr/bin/env python3
"""Tables larger than the memory budget, baked and written slab by slab.

Usage: slabbed.py BAKE WORKDIR

Bakes a generic N_p table set (three lobe tables of 32 beta x 16 sigma_a x 64 theta_d x 384 phi,
151 MB of float32 values: 2.4 times the 64 MiB budget, which also covers the program itself) three
ways: slab by slab with 1 and 2 threads under --memory-budget, and held whole (no budget; tables
plus the in-memory file image, over 4 times the budget). Checks that
  - `--check` reports a slabbed plan whose peak lies within the budget;
  - the peak resident memory of each slabbed bake (getrusage of the child) stays within the
    budget, while the whole bake's is over 3 times it (the tables really are larger than the budget);
  - the two slabbed files are byte-for-byte identical (thread count does not matter);
  - the slabbed file holds exactly the whole bake's values in every dataset, and the same
    checksum, metadata, table index and per-table descriptions (h5py, bit for bit); the whole
    bake's checksum is computed from the tables in memory, the slabbed one while streaming;
  - EXR output is refused under a budget the tables exceed: one line, exit 1, no file;
  - a full disk (a file-size limit) in the middle of the slabs: one line, exit 1, no file left.
"""
import filecmp
import json
import os
import shutil
import sys

import h5py
import numpy as np

import child_peak

BAKE, WORK = sys.argv[1], sys.argv[2]
BUDGET_MIB = 64
failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL: " + msg)


def config(directory, formats=("hdf5",), **np_extra):
    np_table = {"normalize": "energy",
                "axes": {"theta_d": {"count": 64, "range_deg": [0, 85]}, "phi": {"count": 384},
                         "sigma_a": {"count": 16, "range": [0, 4]}, "beta": {"count": 32, "range_deg": [2, 20]}}}
    np_table.update(np_extra)
    return {
        "name": "slabbed",
        "lobes": {"explicit": ["R", "TT", "TRT"], "residual": True},
        "quadrature": {"method": "fourier", "tolerance": 1e-6},
        "tables": {"np": np_table,
                   "mp": {"axes": {"theta_i": {"count": 32, "range_deg": [-85, 85]}, "theta_r": {"count": 32, "range_deg": [-85, 85]}, "beta": {"count": 8, "range_deg": [2, 20]}}}},
        "output": {"directory": directory, "basename": "s", "formats": list(formats), "hdf5": {"compression": 1}, "sampling_data": False},
    }


def write_config(path, doc):
    with open(path, "w") as f:
        json.dump(doc, f)


def peak_mib_of(args, file_size_limit=None):
    return child_peak.peak_mib_of(args, WORK, file_size_limit)


def main():
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    cfg = os.path.join(WORK, "slabbed.json")
    budget = ["--memory-budget", str(BUDGET_MIB)]

    # --check: the plan.
    write_config(cfg, config(os.path.join(WORK, "t1")))
    rc, out, err, _ = peak_mib_of([BAKE, "--config", cfg, "--check"] + budget)
    if rc != 0 or "slab by slab" not in out:
        fail("--check under a %d MiB budget: rc %d, expected a slabbed plan: %s %s" % (BUDGET_MIB, rc, out, err))
    else:
        peak = float(out.split("peak about ")[1].split()[0])
        print("--check: planned peak %.1f MiB within the %d MiB budget" % (peak, BUDGET_MIB))
        if peak > BUDGET_MIB:
            fail("--check plans a peak of %.1f MiB over the %d MiB budget" % (peak, BUDGET_MIB))

    # Slab by slab with 1 and 2 threads, and held whole.
    files = {}
    for label, extra, directory in (("slabbed, 1 thread", budget + ["--threads", "1"], "t1"),
                                    ("slabbed, 2 threads", budget + ["--threads", "2"], "t2"),
                                    ("held whole, 2 threads", ["--threads", "2"], "whole")):
        write_config(cfg, config(os.path.join(WORK, directory)))
        rc, out, err, peak = peak_mib_of([BAKE, "--config", cfg, "--quiet"] + extra)
        files[directory] = os.path.join(WORK, directory, "s.h5")
        size = os.path.getsize(files[directory]) / 1048576.0 if rc == 0 else 0
        print("%s: rc %d, peak RSS %.1f MiB, file %.1f MiB" % (label, rc, peak, size))
        if rc != 0:
            fail("%s: rc %d: %s" % (label, rc, err.strip()))
            continue
        if directory != "whole" and peak > BUDGET_MIB:
            fail("%s: peak RSS %.1f MiB over the %d MiB budget" % (label, peak, BUDGET_MIB))
        if directory == "whole" and peak < 3 * BUDGET_MIB:
            fail("held whole: peak RSS %.1f MiB; the table is meant to be several times the %d MiB budget" % (peak, BUDGET_MIB))
    if failures:
        return

    if not filecmp.cmp(files["t1"], files["t2"], shallow=False):
        fail("slabbed bakes with 1 and 2 threads differ byte for byte")
    else:
        print("slabbed files with 1 and 2 threads: identical bytes")

    def text(attr):
        return attr.decode() if isinstance(attr, bytes) else str(attr)

    with h5py.File(files["t1"], "r") as a, h5py.File(files["whole"], "r") as b:
        for key in ("hairlut_checksum", "hairlut_metadata", "hairlut_tables", "hairlut_format_version"):
            if text(a.attrs[key]) != text(b.attrs[key]):
                fail("root attribute %s differs between the slabbed and the whole bake" % key)
        paths = json.loads(text(b.attrs["hairlut_tables"]))
        compared = 0
        for p in paths:
            x, y = a[p][...], b[p][...]
            if x.dtype != y.dtype or x.shape != y.shape or x.tobytes() != y.tobytes():
                fail("dataset %s differs between the slabbed and the whole bake" % p)
            if text(a[p].attrs["hairlut_table"]) != text(b[p].attrs["hairlut_table"]):
                fail("description of %s differs" % p)
            compared += x.size
        print("slabbed vs whole: %d datasets, %d values, bit-identical; checksum %s in both" %
              (len(paths), compared, text(a.attrs["hairlut_checksum"])))

    # Refusals under the budget.
    write_config(cfg, config(os.path.join(WORK, "exr"), formats=("hdf5", "exr")))
    rc, out, err, _ = peak_mib_of([BAKE, "--config", cfg, "--quiet"] + budget)
    if rc != 1 or "output.exr" not in err or err.count("\n") != 1:
        fail("EXR output of a slabbed table: expected one line naming output.exr and exit 1, got rc %d: %s" % (rc, err))
    if os.path.exists(os.path.join(WORK, "exr")) and os.listdir(os.path.join(WORK, "exr")):
        fail("EXR refusal left files: %s" % os.listdir(os.path.join(WORK, "exr")))

    # A full disk in the middle of the slabs: one line, exit 1, nothing left behind.
    write_config(cfg, config(os.path.join(WORK, "full")))
    rc, out, err, _ = peak_mib_of([BAKE, "--config", cfg, "--quiet"] + budget, file_size_limit=20 << 20)
    left = os.listdir(os.path.join(WORK, "full")) if os.path.isdir(os.path.join(WORK, "full")) else []
    if rc != 1 or "cannot write" not in err or err.count("\n") != 1 or left:
        fail("slabbed bake onto a full disk: expected one line 'cannot write' and exit 1 with no file left, got rc %d, files %s: %s" %
             (rc, left, err))
    else:
        print("full disk during the slabs: exit 1, %s" % err.strip()[:160])

    if failures:
        return
    print("all slabbed checks passed")


main()
sys.exit(1 if failures else 0)
