"""Sweep of every numeric config field with extreme values (hostile.py's probe config-sweep).

The fields are read from schemas/hairlut-config.schema.json (every property of type number or
integer, array items and keyed maps included), so that a field added to the schema is swept
without a change here. Each field is set, in the tiny base config that has its section, to each
of VALUES (and to NaN, which JSON cannot carry: the parser must refuse it). Each case must end in
one of:
  - refused: exit 1 or 2 with one line `bake-hair-luts: error: ...`;
  - baked: exit 0, and the validator then reads the file it wrote (exit 0 or 1: it loaded the
    tables and ran its checks; exit 2 would mean the bake wrote a file its own loader refuses).
A signal, a time limit reached, several lines of error, or a baked file that is refused is a
failure. WORKERS cases run at once.
"""
import copy
import json
import math
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

VALUES = [0, -0.0, 5e-324, 2.2e-308, 1e-300, 1e-100, 1e-20, 1e-15, 1e-10, 1e300, 1.7976931348623157e308, -1, -1e-300, -1e300]
# The CI probes' share (hostile.py config-sweep, config-sweep-ds): each place a field lands in
# takes PER_PLACE of the values (NaN included), the next ones in turn from place to place, so that
# every value still meets about a fifteenth of the places in every run and every place is set.
# None: every value at every place (the full sweep, run by hand: see docs/reliability.md).
PER_PLACE = None
WORKERS = max(1, min(8, os.cpu_count() or 1))
# Whether the validator runs its worst-point search on each baked case. The quick probe (CI) skips
# it: the sweep looks for crashes, hangs and unreadable files, and the search's own edges are
# tested by test_worst_point_search; it multiplies each case's validation time.
SEARCH = True


def base_configs():
    """Tiny configs, one per kind of section; a field is swept in the first base that has its
    top-level section (or, for optional sections, whose key path already exists)."""
    axes3 = {"theta_d": {"count": 3, "range_deg": [0, 60]}, "phi": {"count": 5},
             "sigma_a": {"count": 2, "range": [0, 1]}, "beta": {"count": 2, "range_deg": [8, 20]}}
    deon = {
        "name": "sweep", "model": "deon2011", "fiber": {"eta": 1.55},
        "lobes": {"explicit": ["R", "TT"], "residual": True, "fold_below": 0.0, "tilt_deg": {"R": -4, "TT": 2, "residual": 6}},
        "quadrature": {"order": 32, "energy_order": 32},
        "tables": {"np": {"axes": copy.deepcopy(axes3),
                          "energy_axes": {"sigma_a": {"count": 2, "range": [0, 1]}, "theta_d": {"count": 3, "range_deg": [0, 60]}}},
                   "mp": {"axes": {"theta_i": {"count": 3, "range_deg": [-60, 60]}, "theta_r": {"count": 3, "range_deg": [-60, 60]},
                                   "beta": {"count": 2, "range_deg": [5, 15]}}},
                   "melanin": {"axes": {"eumelanin": {"count": 2, "range": [0, 2]}, "pheomelanin": {"count": 2, "range": [0, 1]}},
                               "path_length": 2.0},
                   },
        "validate": {"thresholds": {"furnace_direct": 1e-3}},
        "output": {"basename": "s", "formats": ["hdf5"], "hdf5": {"compression": 1}},
    }
    # Dual scattering apart: its validation takes about 30 s however small the tables.
    ds = copy.deepcopy(deon)
    ds["tables"] = {"dual_scattering": {"axes": {"theta_i": {"count": 3, "range_deg": [0, 80]}, "beta": {"count": 2, "range_deg": [4, 20]},
                                                 "sigma_a": {"count": 2, "range": [0, 2]}},
                                        "lobe_scale": {"R": 1.0}, "density_factor": 0.7}}
    bands = copy.deepcopy(deon)
    bands["tables"] = {"np": {"axes": {"beta": {"count": 2, "range_deg": [2, 20], "spacing": "log"}, "sigma_a": {"count": 2, "range": [0, 2]},
                                       "theta_d": {"count": 3, "range_deg": [0, 60]}, "phi": {"count": 5}},
                              "beta_bands": [{"beta": {"count": 2, "range_deg": [2, 6]}, "sigma_a": {"count": 2}, "theta_d": {"count": 3},
                                              "phi": {"count": 5}},
                                             {"beta": {"count": 2, "range_deg": [6, 20]}}]}}
    target = copy.deepcopy(deon)
    target["tables"] = {"np": {"axes": copy.deepcopy(axes3), "target_error": 0.05, "target_points": 256}}
    fourier = {"name": "sweep-fourier", "lobes": {"explicit": ["R", "TT"], "residual": True},
               "quadrature": {"method": "fourier", "tolerance": 1e-6},
               "tables": {"np": {"representation": "fourier",
                                 "axes": {"beta": {"range_deg": [5, 20]}, "sigma_a": {"count": 3, "range": [0, 2]},
                                          "theta_d": {"count": 4, "range_deg": [0, 60]}},
                                 "fourier": {"tolerance": 1e-3}}},
               "output": {"basename": "s", "formats": ["hdf5"]}}
    marschner = {"name": "sweep-marschner", "model": "marschner2003", "fiber": {"eta": 1.55}, "lobes": {"explicit": ["R", "TT", "TRT"]},
                 "marschner": {"caustic": {"k_G": 0.5, "w_c_deg": 15, "delta_eta_prime": 0.3, "delta_h_max": 0.5}, "eccentricity": 0.9,
                               "longitudinal": {"alpha_R_deg": -5}},
                 "tables": {"np": {"axes": {"theta_d": {"count": 3, "range_deg": [0, 80]}, "phi": {"count": 9},
                                            "sigma_a": {"count": 2, "range": [0, 2]}, "phi_h": {"count": 3, "range_deg": [0, 90]}}},
                            "mp": {"axes": {"theta_i": {"count": 3, "range_deg": [-80, 80]}, "theta_r": {"count": 3, "range_deg": [-80, 80]},
                                            "beta": {"count": 2, "range_deg": [4, 12]}}}},
                 "output": {"basename": "s", "formats": ["hdf5"]}}
    kajiya = {"name": "sweep-kajiya", "model": "kajiya1989", "kajiya_kay": {"kd": 0.1, "ks": 1.0},
              "tables": {"mp": {"axes": {"theta_i": {"count": 3, "range_deg": [-80, 80]}, "theta_r": {"count": 3, "range_deg": [-80, 80]},
                                         "beta": {"count": 2, "range_deg": [4, 12]}}}},
              "output": {"basename": "s", "formats": ["hdf5"]}}
    scene = {"name": "sweep-scene", "lobes": {"explicit": ["R", "TT", "TRT"], "residual": True}, "quadrature": {"order": 32},
             "tables": {"np": {"axes": {"theta_d": {"count": 3, "range_deg": [0, 60]}, "phi": {"count": 5}}},
                        "mp": {"axes": {"theta_i": {"count": 3, "range_deg": [-60, 60]}, "theta_r": {"count": 3, "range_deg": [-60, 60]}}}},
             "scene": {"materials": [{"name": "a", "melanin": {"eumelanin": 0.5, "pheomelanin": 0.1},
                                      "beta_deg": {"R": 5, "TT": 3, "TRT": 10}, "beta_n_deg": {"R": 5, "TT": 3, "TRT": 10}},
                                     {"name": "b", "sigma_a": [0.2, 0.3, 0.4], "beta_deg": {"R": 6, "TT": 3, "TRT": 12}}]},
             "output": {"basename": "s", "formats": ["hdf5"]}}
    engine = {"name": "sweep-engine", "lobes": {"explicit": ["R", "TT", "TRT"], "residual": True},
              "quadrature": {"method": "fourier", "tolerance": 1e-6},
              "tables": {"engine": {"preset": "unity-hdrp-hair", "density_factor": 0.7,
                                    "unity": {"radial_smoothness": 0.5, "cuticle_angle_deg": 3, "attenuation_scale": 1.0}}},
              "output": {"basename": "s", "formats": ["hdf5"]}}
    return [("deon", deon), ("ds", ds), ("bands", bands), ("target", target), ("fourier", fourier), ("marschner", marschner),
            ("kajiya", kajiya), ("scene", scene), ("engine", engine)]


def schema_fields(schema_path):
    """Paths of the schema's numeric properties: lists of keys, "[]" for an array's items (the
    sweep sets each existing item in turn) and "*" for a keyed map's values."""
    schema = json.load(open(schema_path))
    defs = schema.get("definitions", schema.get("$defs", {}))
    found = []

    def walk(node, path, depth):
        if depth > 14 or not isinstance(node, dict):
            return
        if "$ref" in node:
            walk(defs[node["$ref"].split("/")[-1]], path, depth + 1)
            return
        t = node.get("type")
        types = t if isinstance(t, list) else [t]
        if "number" in types or "integer" in types:
            if path not in found:
                found.append(path)
        for key, sub in node.get("properties", {}).items():
            walk(sub, path + [key], depth + 1)
        items = node.get("items")
        if isinstance(items, dict):
            walk(items, path + ["[]"], depth + 1)
        elif isinstance(items, list):
            for sub in items:
                walk(sub, path + ["[]"], depth + 1)
        if isinstance(node.get("additionalProperties"), dict):
            walk(node["additionalProperties"], path + ["*"], depth + 1)
        for sub in node.get("patternProperties", {}).values():
            walk(sub, path + ["*"], depth + 1)
        for key in ("oneOf", "anyOf", "allOf"):
            for sub in node.get(key, []):
                walk(sub, path, depth + 1)
        for key in ("if", "then", "else"):
            if key in node:
                walk(node[key], path, depth + 1)

    walk(schema, [], 0)
    return found


def targets(config, path):
    """Where `path` lands in `config`: a list of (container, key) pairs, following existing arrays
    and maps only; the last key is created if its parent exists."""
    places = [(None, config)]
    for i, key in enumerate(path):
        last = i == len(path) - 1
        nxt = []
        for _, node in places:
            if key == "[]":
                if isinstance(node, list):
                    nxt += [(node, k) if last else (None, node[k]) for k in range(len(node))]
            elif key == "*":
                if isinstance(node, dict):
                    nxt += [(node, k) if last else (None, node[k]) for k in node]
            elif isinstance(node, dict):
                if last:
                    nxt.append((node, key))
                elif key in node:
                    nxt.append((None, node[key]))
        places = nxt
    return places


def alternative_axis(axis, form):
    """The axis with its nodes given as `form` (range, range_deg, values or values_deg)."""
    if "range_deg" in axis:
        lo, hi = (math.radians(x) for x in axis["range_deg"])
    elif "range" in axis:
        lo, hi = axis["range"]
    else:
        lo, hi = 0.1, 0.5
    count = max(2, min(int(axis.get("count", 3)), 3))
    nodes = [lo + (hi - lo) * k / (count - 1) for k in range(count)]
    out = {k: v for k, v in axis.items() if k not in ("range", "range_deg", "values", "values_deg", "count", "spacing")}
    if form == "range":
        out.update(count=axis.get("count", 3), range=[lo, hi])
    elif form == "range_deg":
        out.update(count=axis.get("count", 3), range_deg=[math.degrees(lo), math.degrees(hi)])
    elif form == "values":
        out["values"] = nodes
    else:
        out["values_deg"] = [math.degrees(x) for x in nodes]
    return out


def cases(schema_path):
    """(name, config document) for every field, base and value; and the fields no base reaches."""
    out, unreached = [], []
    bases = base_configs()
    turn = [0]

    def values():
        every = VALUES + ["NaN"]
        if PER_PLACE is None:
            return every
        picked = [every[(turn[0] + k) % len(every)] for k in range(min(PER_PLACE, len(every)))]
        turn[0] += PER_PLACE
        return picked
    for path in schema_fields(schema_path):
        reached = False
        for base_name, base in bases:
            probe = copy.deepcopy(base)
            places = targets(probe, path)
            for index in range(len(places)):
                for value in values():
                    doc = copy.deepcopy(base)
                    container, key = targets(doc, path)[index]
                    container[key] = value
                    label = "%s %s%s = %r" % (base_name, ".".join(path), "" if len(places) == 1 else "#%d" % index, value)
                    out.append((label, doc))
                reached = True
            if reached:
                break
        if not reached and len(path) >= 2 and path[-1] == "[]" and path[-2] in ("range", "range_deg", "values", "values_deg"):
            # An axis given by another form: the base's axis rewritten in this form, then swept.
            for base_name, base in bases:
                axes = targets(copy.deepcopy(base), path[:-2])
                if not axes or not all(isinstance(c, dict) and isinstance(c.get(k), dict) for c, k in axes):
                    continue
                alt = copy.deepcopy(base)
                for container, key in targets(alt, path[:-2]):
                    container[key] = alternative_axis(container[key], path[-2])
                for index in range(len(targets(alt, path))):
                    for value in values():
                        doc = copy.deepcopy(alt)
                        container, key = targets(doc, path)[index]
                        container[key] = value
                        out.append(("%s %s#%d = %r" % (base_name, ".".join(path), index, value), doc))
                reached = True
                break
        if not reached:
            unreached.append(".".join(path))
    return out, unreached


def run_case(bake, validate, work, index, label, doc):
    d = os.path.join(work, "c%04d" % index)
    os.makedirs(d, exist_ok=True)
    cfg = os.path.join(d, "c.json")
    text = json.dumps(doc, allow_nan=True)
    with open(cfg, "w") as f:
        f.write(text)
    out = os.path.join(d, "out")
    try:
        p = subprocess.run([bake, "--config", cfg, "--output-dir", out, "--quiet", "--force"], capture_output=True, text=True, timeout=90,
                           errors="replace")
    except subprocess.TimeoutExpired:
        return "hang", label, "bake ran over 90 s"
    lines = [l for l in p.stderr.splitlines() if l.strip()]
    if p.returncode < 0:
        return "crash", label, "bake died of signal %d" % -p.returncode
    if p.returncode != 0:
        if p.returncode in (1, 2) and len(lines) == 1 and lines[0].startswith("bake-hair-luts: error: "):
            return "refused", label, lines[0][:200]
        return "bad-error", label, "bake exit %d: %s" % (p.returncode, p.stderr[-300:])
    h5 = os.path.join(out, "s.h5")
    try:
        v = subprocess.run([validate, h5, "--quiet", "--max-points", "200", "--out", os.path.join(d, "r")] + ([] if SEARCH else ["--no-search"]),
                           capture_output=True, text=True,
                           timeout=180, errors="replace")
    except subprocess.TimeoutExpired:
        return "hang", label, "validate ran over 180 s"
    if v.returncode < 0:
        return "crash", label, "validate died of signal %d" % -v.returncode
    if v.returncode not in (0, 1):
        return "unreadable", label, "baked, then validate exit %d: %s" % (v.returncode, v.stderr.strip()[-300:])
    import shutil
    shutil.rmtree(d, ignore_errors=True)
    return "baked", label, "validate exit %d" % v.returncode


def sweep(bake, validate, work, schema_path, only=None):
    all_cases, unreached = cases(schema_path)
    if only:  # "a,b": those bases only; "-a,b": every base but those
        names = only.lstrip("-").split(",")
        keep = not only.startswith("-")
        all_cases = [c for c in all_cases if any(c[0].startswith(o + " ") for o in names) == keep]
    results = []
    with ThreadPoolExecutor(WORKERS) as pool:
        futures = [pool.submit(run_case, bake, validate, work, i, label, doc) for i, (label, doc) in enumerate(all_cases)]
        for f in futures:
            results.append(f.result())
            kind, label, why = results[-1]
            if kind not in ("refused", "baked"):
                print("FAIL %-10s %s: %s" % (kind, label, why), flush=True)
    return results, unreached


def summary(results, unreached):
    counts = {}
    for kind, _, _ in results:
        counts[kind] = counts.get(kind, 0) + 1
    return "cases %d: %s; fields no base reaches: %s" % (len(results), counts, unreached or "none")


if __name__ == "__main__":
    # sweep.py BAKE VALIDATE WORKDIR SCHEMA [BASES (comma-separated)] [PER_PLACE]
    bake, validate, work, schema = sys.argv[1:5]
    only = sys.argv[5] if len(sys.argv) > 5 and sys.argv[5] else None
    if len(sys.argv) > 6:
        PER_PLACE = int(sys.argv[6])
    results, unreached = sweep(bake, validate, work, schema, only)
    print(summary(results, unreached))
