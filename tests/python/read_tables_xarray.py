#!/usr/bin/env python3
"""xarray (Debian's python3-xarray with python3-h5netcdf) opens each group of a hairlut HDF5 file
and sees the axes as coordinates with units; the values equal what h5py reads."""
import sys

import h5py
import numpy as np
import xarray as xr

path = sys.argv[1]
with h5py.File(path, "r") as f:
    groups = [g for g in f.keys() if isinstance(f[g], h5py.Group) and g != "materials"]
    if "materials" in f:  # a scene's materials, whose groups share their axes' scales (hard links)
        groups += ["materials/" + m for m in f["materials"].keys()]
    checked = 0
    for g in groups:
        ds = xr.open_dataset(path, group=g, engine="h5netcdf")
        for name, var in ds.data_vars.items():
            ref = f[g][name]
            assert list(var.dims) == [ref.dims[k][0].name.split("/")[-1] for k in range(ref.ndim)], (g, name, var.dims)
            for dim in var.dims:
                assert dim in ds.coords, (g, name, dim)
                assert "units" in ds.coords[dim].attrs, (g, dim)
                assert np.array_equal(ds.coords[dim].values, f[g][dim][()])
            assert np.array_equal(var.values, ref[()], equal_nan=False), (g, name)
            checked += 1
print(f"xarray {xr.__version__}: {checked} variables in {len(groups)} groups with coordinates")
