#!/usr/bin/env python3
"""The hairlut Python module against the C++ library and independent readers.

Arguments: the hairlut-eval binary, a baked HDF5 table file, the default config, a scratch
directory. Values of every evaluation function must equal hairlut-eval's (the C++ library
through its tool, printed as round-trip JSON) to a few ulps; a table loaded by the module must
equal what h5py reads (values and dimension-scale coordinates) and, at its nodes, the baker's N_p
to float32 rounding; a table baked from a dict must equal the same config baked from a file.
"""
import copy
import json
import math
import os
import subprocess
import sys

import h5py
import numpy as np

import hairlut

EVAL, TABLE, CONFIG, WORK = sys.argv[1:5]
os.makedirs(WORK, exist_ok=True)
failures = []


def eval_json(*args):
    out = subprocess.run([EVAL, "--json", *map(str, args)], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def close(what, got, want, rel=4e-15, abs_=0.0):
    got, want = float(got), float(want)
    if not abs(got - want) <= rel * abs(want) + abs_:
        failures.append(f"{what}: python {got!r} != C++ {want!r}")


d = np.radians
checked = 0

# M_p
for beta, ti, tr, alpha in [(5, 30, -34, -4), (0.5, 10, -10, 0), (30, -80, 85, 6)]:
    ref = eval_json("mp", "--beta-deg", beta, "--theta-i-deg", ti, "--theta-r-deg", tr, "--alpha-deg", alpha)
    close(f"M_p{(beta, ti, tr, alpha)}", hairlut.longitudinal_mp(d(beta), d(ti), d(tr), d(alpha)), ref["M"])
    checked += 1

# N_p by the three methods; broadcasting equals scalar calls.
for lobe, beta, td, phi, sigma in [("TRT", 5, 20, 30, 0.5), ("TT", 0.72, 20, 170, 0.1), ("R", 10, 60, 100, 0), ("TRRT", 3, 40, 15, 2)]:
    common = ["--lobe", lobe, "--beta-deg", beta, "--theta-d-deg", td, "--phi-deg", phi, "--sigma-a", sigma]
    for method in ["baker", "adaptive", "gauss-legendre"]:
        ref = eval_json("np", *common, "--method", method)
        got = hairlut.azimuthal_np(lobe, d(phi), d(td), sigma, d(beta), method=method)
        close(f"N_{lobe}{(beta, td, phi, sigma)} {method}", got, ref["N"])
        checked += 1
phis = d(np.array([[0.0, 30.0, 90.0], [150.0, 170.0, 180.0]]))
grid = hairlut.azimuthal_np("TT", phis, d(20), 0.1, d(2.0))
if grid.shape != phis.shape:
    failures.append(f"N_p over a {phis.shape} phi array has shape {grid.shape}")
for idx in np.ndindex(phis.shape):
    if grid[idx] != hairlut.azimuthal_np("TT", phis[idx], d(20), 0.1, d(2.0)):
        failures.append(f"broadcast N_p differs from the scalar call at phi {phis[idx]}")

# Lobe energies
ref = eval_json("energy", "--sigma-a", 0.3, "--theta-d-deg", 50, "--lobes", 4, "--residual")
got = hairlut.lobe_energies(d(50), 0.3, lobes=4, residual=True)
for k, row in enumerate(ref["lobes"]):
    close(f"energy {row['lobe']}", got[k], row["energy"])
    checked += 1

# White furnace and dual scattering with per-lobe roughness and tilts
betas, alphas, thetas = [6, 3, 12, 12], [-4, 2, 6, 6], [0, 45, 80]
ref = eval_json("furnace", "--beta-deg", ",".join(map(str, betas)), "--alpha-deg", ",".join(map(str, alphas)), "--lobes", 3,
                "--residual", "--theta-i-deg", ",".join(map(str, thetas)))
got = hairlut.furnace(d(np.array(thetas, float)), d(np.array(betas, float)), d(np.array(alphas, float)), lobes=3, residual=True)
for k, row in enumerate(ref["E_theta_i"]):
    close(f"furnace E({row['theta_i_deg']})", got["E"][k], row["E"], rel=1e-14)
    close(f"furnace TRT({row['theta_i_deg']})", got["per_lobe"][k][2], row["TRT"], rel=1e-14)
    checked += 2
ref = eval_json("dual", "--beta-deg", 10, "--lobes", 3, "--residual", "--sigma-a", 0.4, "--theta-i-deg", "0,60")
got = hairlut.dual_scattering(d(np.array([0.0, 60.0])), d(10), lobes=3, residual=True, sigma_a=0.4)
for k, row in enumerate(ref["dual_scattering"]):
    for key in ["E", "a_f", "a_b", "A_b"]:
        close(f"dual {key}({row['theta_i_deg']})", got[key][k], row[key], rel=1e-14)
        checked += 1
    close(f"dual sigma_b({row['theta_i_deg']})", math.degrees(got["sigma_b"][k]), row["sigma_b_deg"], rel=1e-14)

# A loaded table: equal to h5py's reading; at nodes, the baker's N_p rounded to float32.
tables = hairlut.load_tables(TABLE)
with h5py.File(TABLE, "r") as f:
    for path, t in tables.items():
        ds = f[path]
        if not np.array_equal(t.values, ds[()]):
            failures.append(f"{path}: values differ from h5py's")
        for k, dim in enumerate(t.dims):
            scale = ds.dims[k][0]
            if not np.array_equal(t.coords[dim], scale[()]):
                failures.append(f"{path}: coordinates of {dim} differ from the dimension scale")
        checked += 1
trt = tables["np/TRT"]
if trt.dims != ("beta", "sigma_a", "theta_d", "phi"):
    failures.append(f"np/TRT dims {trt.dims}")
tolerance = json.loads(tables.metadata["config"])["quadrature"]["tolerance"]
# A normalized table stores N_p / E_p and names its energy table as "factor"; the energy table's
# axes refine N_p's, so at N_p's nodes N_p = shape x energy at an energy node.
factor = trt.description.get("attributes", {}).get("factor")
energy = tables[factor] if factor else None


def node_value(t, ib, ks, it, jp):
    v = float(t.values[ib, ks, it, jp])
    if energy is None:
        return v, 1
    i = int(np.flatnonzero(np.isclose(energy.coords["sigma_a"], t.coords["sigma_a"][ks], rtol=1e-12, atol=0))[0])
    j = int(np.flatnonzero(np.isclose(energy.coords["theta_d"], t.coords["theta_d"][it], rtol=1e-12, atol=1e-15))[0])
    # Format 3.0 (2.1 before): an energy table reaching theta_d = 90 deg stores E_p / cos^n(theta_d) (docs/table-format.md);
    # TRT's factor has no grazing_absorption bracket.
    attrs = energy.description.get("attributes", {})
    if "grazing_absorption" in attrs:
        failures.append("np/TRT's energy table carries grazing_absorption, which only the residual's should")
    g = math.cos(float(t.coords["theta_d"][it])) ** attrs.get("cos_theta_d_power", 0)
    return v * float(energy.values[i, j]) * g, 3  # two float32 roundings and the product


# An upper bound of the lobe's peak over the table (the baker's tolerance is relative to it).
peak = float(trt.values.max()) * (float(energy.values.max()) if energy is not None else 1.0)
for ib, ks, it, jp in [(0, 0, 0, 0), (3, 2, 7, 10), (7, 7, 19, 48), (1, 4, 12, 30)]:
    c = trt.coords
    direct = eval_json("np", "--lobe", "TRT", "--beta-deg", math.degrees(c["beta"][ib]), "--sigma-a", repr(float(c["sigma_a"][ks])),
                       "--theta-d-deg", math.degrees(c["theta_d"][it]), "--phi-deg", math.degrees(c["phi"][jp]), "--tolerance", tolerance)["N"]
    value, roundings = node_value(trt, ib, ks, it, jp)
    # float32 storage (2^-24 relative per rounding) and the baker's tolerance (relative to the peak)
    close(f"np/TRT node {(ib, ks, it, jp)} against hairlut-eval", value, direct, rel=2.0**-24 * 1.01 * roundings,
          abs_=1e-9 * peak)
    checked += 1

# Bake from a dict and from a file: a small config derived from the default one.
config = json.load(open(CONFIG))
small = copy.deepcopy(config)
small["name"] = "python-small"
small["tables"] = {"np": copy.deepcopy(config["tables"]["np"])}
small["tables"]["np"].pop("normalize", None)  # N_p itself at the nodes
small["tables"]["np"].pop("energy_axes", None)
axes = small["tables"]["np"]["axes"]
axes["theta_d"]["count"], axes["phi"]["count"], axes["sigma_a"]["count"], axes["beta"]["count"] = 4, 13, 3, 2
small["output"] = {"directory": WORK, "basename": "python-small", "formats": ["hdf5"]}
small.pop("$schema", None)
baked = hairlut.bake(small)
tt = baked["np/TT"]
c = tt.coords
for ib, ks, it, jp in [(0, 0, 0, 0), (1, 2, 3, 12), (0, 1, 2, 6)]:
    direct = hairlut.azimuthal_np("TT", c["phi"][jp], c["theta_d"][it], c["sigma_a"][ks], c["beta"][ib], tolerance=tolerance)
    close(f"baked np/TT node {(ib, ks, it, jp)} against azimuthal_np", tt.values[ib, ks, it, jp], direct, rel=2.0**-24 * 1.01,
          abs_=1e-9 * float(tt.values.max()))
    checked += 1
config_file = os.path.join(WORK, "python-small.json")
with open(config_file, "w") as f:
    json.dump(small, f)
from_file = hairlut.bake(config_file, write=True)
if not from_file.files or not all(os.path.exists(p) for p in from_file.files):
    failures.append(f"bake(write=True) files: {from_file.files}")
if from_file.config_hash != baked.config_hash:
    failures.append("a config baked from a dict and from a file have different hashes")
reloaded = hairlut.load_tables(os.path.join(WORK, "python-small.h5"))
for path, t in baked.items():
    if not np.array_equal(t.values, from_file[path].values) or not np.array_equal(t.values, reloaded[path].values):
        failures.append(f"{path}: dict bake, file bake and the written file differ")
    checked += 1

# Errors are Python exceptions, not crashes.
for call, exc in [(lambda: hairlut.azimuthal_np("TT", 0.0, 0.3, 0.1, -1.0), ValueError),
                  (lambda: hairlut.azimuthal_np("TXT", 0.0, 0.3, 0.1, 0.1), ValueError),
                  (lambda: hairlut.load_tables(CONFIG), OSError),
                  (lambda: hairlut.bake({"name": "x"}), ValueError)]:
    try:
        call()
        failures.append(f"no {exc.__name__} raised")
    except exc:
        pass

# xarray, when installed
try:
    import xarray  # noqa: F401
    da = trt.to_xarray()
    if da.dims != trt.dims or not np.array_equal(da.coords["phi"].values, trt.coords["phi"]) or da.attrs["units"] != trt.units:
        failures.append("to_xarray: dims, coordinates or units differ")
    xr_note = f"xarray {xarray.__version__}"
except ImportError:
    xr_note = "xarray not installed"

if failures:
    print("\n".join(failures))
    sys.exit(1)
print(f"python module ok: hairlut {hairlut.__version__}, {checked} comparisons with the C++ library and h5py, {xr_note}")
