#!/usr/bin/env python3
"""bake-hair-luts --check against the bake, for every config in tables/configs (by hand, not in CI:
it bakes them all, generic.json's 780 MiB included).

Usage: estimate_configs.py BAKE WORKDIR [check] [NAMES]

Each config is copied with its output directory moved under WORKDIR (plus generic.json with 8 β
nodes, and that one uncompressed with a float OpenEXR beside it); --check --threads 2 gives the
planned peak and disk, the bake (--threads 2) its peak resident memory (getrusage of the child,
as estimate.py measures it) and the files written. With `check` only --check runs, and the
results in WORKDIR/results-check.json beside WORKDIR/results-all.json give the table of
docs/reliability.md. NAMES: a comma-separated list of labels to run.
"""
import json
import os
import shutil
import sys

import child_peak

BAKE, WORK = sys.argv[1], os.path.abspath(sys.argv[2])
MODE = sys.argv[3] if len(sys.argv) > 3 else "all"
ONLY = sys.argv[4].split(",") if len(sys.argv) > 4 else None
CONFIGS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tables", "configs")


def figure(text, before, after):
    return float(text.split(before)[1].split(after)[0].split()[-1])


def variants():
    for name in sorted(os.listdir(CONFIGS)):
        if not name.endswith(".json"):
            continue
        with open(os.path.join(CONFIGS, name)) as f:
            doc = json.load(f)
        yield name[:-5], doc
        if name == "generic.json":
            small = json.loads(json.dumps(doc))
            small["tables"]["np"]["axes"]["beta"]["count"] = 8
            yield "generic-b8", small
            raw = json.loads(json.dumps(small))
            raw["output"].update(formats=["hdf5", "exr"], hdf5={"compression": 0}, exr={"precision": "float"})
            yield "generic-b8-raw-exr", raw


def main():
    os.makedirs(WORK, exist_ok=True)
    path = os.path.join(WORK, "results-%s.json" % MODE)
    results = json.load(open(path)) if os.path.exists(path) else {}
    for label, doc in variants():
        if ONLY and label not in ONLY:
            continue
        out_dir = os.path.join(WORK, "out", label)
        doc["output"]["directory"] = out_dir
        doc.pop("$schema", None)
        cfg = os.path.join(WORK, label + ".json")
        with open(cfg, "w") as f:
            json.dump(doc, f)
        rc, out, err, _ = child_peak.peak_mib_of([BAKE, "--config", cfg, "--check", "--threads", "2"], WORK)
        if rc != 0:
            print("%s: --check exit %d: %s" % (label, rc, err.strip()))
            continue
        r = results.get(label, {})
        r.update(planned=figure(out, "peak about", "MiB"), disk_expected=figure(out, "disk about", "MiB"), disk_bound=figure(out, "at most", "MiB"))
        if MODE == "all":
            shutil.rmtree(out_dir, ignore_errors=True)
            rc, out, err, peak = child_peak.peak_mib_of([BAKE, "--config", cfg, "--quiet", "--force", "--threads", "2"], WORK)
            if rc != 0:
                print("%s: bake exit %d: %s" % (label, rc, err.strip()))
                continue
            r.update(peak=peak, disk=sum(os.path.getsize(os.path.join(out_dir, n)) for n in os.listdir(out_dir)) / 1048576.0)
        results[label] = r
        with open(path, "w") as f:
            json.dump(results, f, indent=1)
        line = "%s: planned peak %.1f MiB, disk expected %.1f MiB (at most %.1f)" % (label, r["planned"], r["disk_expected"], r["disk_bound"])
        if "peak" in r:
            line += "; measured peak %.1f MiB (%+.0f%%), written %.1f MiB (%+.0f%%)" % (
                r["peak"], 100 * (r["planned"] / r["peak"] - 1), r["disk"], 100 * (r["disk_expected"] / r["disk"] - 1))
        print(line, flush=True)


main()
