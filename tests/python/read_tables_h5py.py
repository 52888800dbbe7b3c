#!/usr/bin/env python3
"""A Python client (Debian's python3-h5py) reads a hairlut HDF5 file with its coordinates.

Checks, for every table listed in the sidecar JSON: the dataset exists with the listed shape;
each dimension has exactly one attached dimension scale, named like the axis, with `units` and
`long_name` attributes and the node values the sidecar lists; the root carries the provenance.
Prints one summary line; exits non-zero on the first mismatch.
"""
import json
import re
import sys

import os

import h5py
import jsonschema
import numpy as np

h5_path, sidecar_path = sys.argv[1], sys.argv[2]
sidecar = json.load(open(sidecar_path))
schema_path = os.path.join(os.path.dirname(__file__), "..", "..", "schemas", "hairlut-tables.schema.json")
jsonschema.Draft202012Validator(json.load(open(schema_path))).validate(sidecar)
with h5py.File(h5_path, "r") as f:
    for key in ("hairlut_version", "model", "eta", "config", "config_hash"):
        assert key in f.attrs, f"root attribute {key} missing"
    assert f.attrs["config_hash"] == sidecar["config_hash"]
    count = 0
    for table in sidecar["tables"]:
        ds = f[table["hdf5"]["dataset"]]
        assert list(ds.shape) == table["shape"], (table["path"], ds.shape, table["shape"])
        assert ds.attrs["units"] == table["units"]
        for k, axis in enumerate(table["axes"]):
            scales = list(ds.dims[k].values())
            assert len(scales) == 1, f"{table['path']} dim {k}: {len(scales)} scales"
            assert ds.dims[k].label == "" or ds.dims[k].label == axis["name"]
            scale = scales[0]
            # The scale is named like the axis; its dataset too, with a suffix _2, _3, ... when one
            # group holds different axes of the same name (the dense energy axes of normalized N_p).
            assert list(ds.dims[k].keys()) == [axis["name"]], (table["path"], list(ds.dims[k].keys()))
            assert re.fullmatch(re.escape(axis["name"]) + r"(_[0-9]+)?", scale.name.split("/")[-1]), (scale.name, axis["name"])
            assert scale.attrs["units"] == axis["units"]
            assert scale.attrs["long_name"] == axis["long_name"]
            assert np.array_equal(scale[()], np.array(axis["values"], dtype=np.float64)), table["path"]
        data = ds[()]
        assert np.all(np.isfinite(data)), table["path"]
        # Shifts (dual scattering) are signed; spectral transmittance is negative out of the sRGB gamut; sampling
        # prefix integrals integrate an unclamped interpolant; cosine-series coefficients are signed.
        assert table["quantity"] in ("shift", "transmittance", "sampling_cdf", "fourier_coefficient") or np.all(data >= 0), table["path"]
        count += 1
    # Sibling groups under a group other than the root (the materials of a scene) share each axis
    # of the same name and nodes: one dimension scale, hard-linked into every group by the axis's name.
    first, shared = {}, 0
    for table in sidecar["tables"]:
        group = table["group"]
        if "/" not in group:
            continue
        ds = f[table["hdf5"]["dataset"]]
        for k, axis in enumerate(table["axes"]):
            key = (group.rsplit("/", 1)[0], axis["name"], tuple(axis["values"]))
            scale = ds.dims[k][0]
            if key not in first:
                first[key] = scale
                continue
            assert scale == first[key], (table["path"], axis["name"], "not the siblings' scale")
            assert f[group + "/" + scale.name.split("/")[-1]] == scale, (table["path"], "the scale is not linked into its group")
            shared += 1
print(f"h5py {h5py.__version__}: {count} tables with dimension scales read from {h5_path}"
      + (f" ({shared} attachments to scales shared by sibling groups)" if shared else ""))
