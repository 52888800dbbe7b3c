#!/usr/bin/env python3
"""HDF5 storage of written tables: h5py (an independent reader) and hairlut's reader see the same
tables whatever the storage the writer chose.

Bakes one per-material config at two resolutions (N_p of 48 KiB and of 72 KiB per lobe) with
output.hdf5.compression 0 and 6, and checks:
- the storage is the documented one (docs/table-format.md, "HDF5 layout"): datasets of at most
  4 KiB compact and unfiltered; with compression 6 larger ones chunked with shuffle, deflate and
  Fletcher-32; with compression 0 unfiltered and contiguous;
- h5py reads the same datasets, dtypes, shapes, values (bit for bit), attributes and attached
  dimension scales from both files (the root attributes that record the config aside);
- hairlut's reader (validate-hair-luts) accepts both files and reports the same results for both;
- with compression 0, one and two threads give byte-identical files.
Prints "hdf5 storage ok"; exits non-zero on the first mismatch.
"""
import json
import os
import subprocess
import sys

import h5py
import numpy as np

bake, validate, work = sys.argv[1], sys.argv[2], sys.argv[3]
os.makedirs(work, exist_ok=True)


def config(theta_d_count, compression):
    mats = [{"name": n, "melanin": {"eumelanin": e, "pheomelanin": 0.1}, "beta_deg": {"R": 2.0, "TT": 2.0, "TRT": 2.0}}
            for n, e in (("blond", 0.1), ("dark", 1.2))]
    return {"name": "storage", "model": "deon2011", "fiber": {"eta": 1.55, "absorption_path": "chord"},
            "lobes": {"explicit": ["R", "TT", "TRT"], "residual": False},
            "quadrature": {"method": "fourier", "tolerance": 1e-10},
            "tables": {"np": {"axes": {"theta_d": {"count": theta_d_count, "range_deg": [0, 90], "spacing": "cos"},
                                       "phi": {"count": 64, "symmetry": "full"}}}},
            "scene": {"mode": "per-material", "materials": mats},
            "output": {"directory": ".", "basename": "storage", "formats": ["hdf5"], "hdf5": {"compression": compression}}}


def baked(theta_d_count, compression, threads=1):
    d = os.path.join(work, "t%d-c%d-j%d" % (theta_d_count, compression, threads))
    path = os.path.join(d, "cfg.json")
    os.makedirs(d, exist_ok=True)
    json.dump(config(theta_d_count, compression), open(path, "w"))
    subprocess.run([bake, "--config", path, "--output-dir", d, "--force", "--quiet", "--threads", str(threads)], check=True)
    return os.path.join(d, "storage.h5")


def datasets(f):
    out = []
    f.visititems(lambda n, o: out.append(n) if isinstance(o, h5py.Dataset) else None)
    return out


def check_storage(f, compression):
    for name in datasets(f):
        ds = f[name]
        layout = ds.id.get_create_plist().get_layout()
        nbytes = ds.size * ds.dtype.itemsize
        if nbytes <= 4096:
            want = h5py.h5d.COMPACT
        else:
            want = h5py.h5d.CONTIGUOUS if compression == 0 else h5py.h5d.CHUNKED
        assert layout == want, (name, nbytes, compression, layout, want)
        if want == h5py.h5d.CHUNKED:
            assert ds.compression == "gzip" and ds.compression_opts == compression and ds.shuffle and ds.fletcher32, name
        else:
            assert ds.compression is None and not ds.shuffle and not ds.fletcher32, name


def same_attr(a, b):
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(a, b)
    return a == b


layouts_seen = set()
for theta_d_count in (64, 96):
    files = {c: baked(theta_d_count, c) for c in (0, 6)}
    handles = {c: h5py.File(p, "r") for c, p in files.items()}
    for c, f in handles.items():
        check_storage(f, c)
        layouts_seen.update(f[n].id.get_create_plist().get_layout() for n in datasets(f))
    a, b = handles[0], handles[6]
    assert sorted(a.attrs) == sorted(b.attrs)
    for k in a.attrs:  # the config (hence its hash, the metadata and the checksum over them) names the compression
        if k not in ("config", "config_hash", "hairlut_metadata", "hairlut_checksum"):
            assert same_attr(a.attrs[k], b.attrs[k]), k
    names = datasets(a)
    assert names == datasets(b) and len(names) > 0
    for n in names:
        x, y = a[n], b[n]
        assert x.dtype == y.dtype and x.shape == y.shape, n
        assert x[()].tobytes() == y[()].tobytes(), n
        assert sorted(x.attrs) == sorted(y.attrs), n
        for k in x.attrs:
            if k not in ("DIMENSION_LIST", "REFERENCE_LIST"):
                assert same_attr(x.attrs[k], y.attrs[k]), (n, k)
        is_scale = x.attrs.get("CLASS") == b"DIMENSION_SCALE"
        assert is_scale == (y.attrs.get("CLASS") == b"DIMENSION_SCALE") and is_scale != ("DIMENSION_LIST" in x.attrs), n
        for d in range(0 if is_scale else x.ndim):
            sx, sy = list(x.dims[d].values()), list(y.dims[d].values())
            assert len(sx) == 1 and [s.name for s in sx] == [s.name for s in sy], (n, d)
            assert np.array_equal(sx[0][()], sy[0][()]), (n, d)
    reports = []
    for c, p in files.items():
        out = os.path.join(work, "report-%d-c%d" % (theta_d_count, c))
        # Random points only: the two storages are compared, not the measure (no worst-point search).
        r = subprocess.run([validate, p, "--quiet", "--max-points", "50", "--no-search", "--seed", "1", "--out", out], capture_output=True,
                           text=True)
        assert r.returncode in (0, 1), (p, r.returncode, r.stderr)
        report = json.load(open(os.path.join(out, "report.json")))
        reports.append(json.dumps({k: report[k] for k in ("sanity", "accuracy", "checks")}, sort_keys=True))
    assert reports[0] == reports[1], "the validator reads different tables from the two storages"
    for f in handles.values():
        f.close()
assert layouts_seen == {h5py.h5d.COMPACT, h5py.h5d.CONTIGUOUS, h5py.h5d.CHUNKED}, layouts_seen
one, two = baked(96, 0, 1), baked(96, 0, 2)
assert open(one, "rb").read() == open(two, "rb").read(), "compression 0: files differ between one and two threads"
print("hdf5 storage ok")
