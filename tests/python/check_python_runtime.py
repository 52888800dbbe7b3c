#!/usr/bin/env python3
"""The Python module reads baked tables as a renderer does, raises its own exceptions, and maps NaN
to NaN.

    check_python_runtime.py DEFAULT_H5 SHOW_CONFIG WORK FOURIER_H5

- Exceptions: hairlut.DomainError / ConfigError are ValueErrors and hairlut.IoError an OSError,
  importable from hairlut itself, and raised for a bad argument, a bad config and a missing file.
- NaN in, NaN out: every evaluation function gives NaN exactly where an argument is NaN and, at
  the other points, the values it gives without the NaN points.
- TableSet.sample (the C++ library's interpolation of the file) against direct evaluation of the
  physics (azimuthal_np, longitudinal_mp) at random points between the nodes: within twice the
  default tables' validate threshold accuracy_max_rel (1e-2; twice because N_p is stored as shape
  times energy, each interpolated), relative to the peak of the slice, as the validator measures.
  A Fourier set (tests/configs/valid/fourier.json) read the same way, over the N_p domain its
  coefficient tables stand for (TableSet.domain_dims): within that config's 1e-3, the residual
  relative to its value.
- TableSet.scattering (HairScattering<float>): for a white fiber every sample's weight S / pdf is
  the albedo at wo up to the energy tables' interpolation (the default tables' accuracy_max_rel), weight x pdf is eval at the drawn direction, and pdf() gives
  the sample's pdf; the same prepared for one roughness (Scattering.prepared), and over one
  material of a per-material bake, written and loaded back.
"""

import math
import sys
from pathlib import Path

import numpy as np

import hairlut

h5, show_config, work, fourier_h5 = sys.argv[1], sys.argv[2], Path(sys.argv[3]), sys.argv[4]
work.mkdir(parents=True, exist_ok=True)
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


# Exceptions.
check(issubclass(hairlut.DomainError, ValueError) and issubclass(hairlut.ConfigError, ValueError), "DomainError, ConfigError are ValueErrors")
check(issubclass(hairlut.IoError, OSError), "IoError is an OSError")
for call, exc, what in [(lambda: hairlut.longitudinal_mp(-1.0, 0.0, 0.0), hairlut.DomainError, "beta < 0"),
                        (lambda: hairlut.load_tables(work / "missing.h5"), hairlut.IoError, "a missing file"),
                        (lambda: hairlut.bake({"name": "x", "tables": {"np": {"axis": {}}}}), hairlut.ConfigError, "a bad config")]:
    try:
        call()
        check(False, f"{what}: nothing raised")
    except exc:
        pass
    except Exception as e:  # noqa: BLE001 - the wrong class is the failure reported
        check(False, f"{what}: raised {type(e).__name__}, not hairlut.{exc.__name__}")

# NaN in, NaN out.
rad = np.radians
cases = {
    "longitudinal_mp": lambda a: hairlut.longitudinal_mp(rad(5), rad(30), a),
    "azimuthal_np": lambda a: hairlut.azimuthal_np("TT", a, theta_d=rad(20), sigma_a=0.5, beta=rad(8)),
    "lobe_energies": lambda a: hairlut.lobe_energies(a, sigma_a=0.3, lobes=3, residual=True),
    "furnace": lambda a: hairlut.furnace(a, beta=rad(10))["E"],
    "dual_scattering": lambda a: hairlut.dual_scattering(a, beta=rad(10), sigma_a=0.4)["a_f"],
}
x = np.array([0.1, np.nan, 0.5, np.nan, 0.9])
for name, f in cases.items():
    got, clean = f(x), f(x[[0, 2, 4]])
    nan_rows = np.isnan(got).reshape(len(x), -1).all(axis=1)
    check(list(nan_rows) == [False, True, False, True, False], f"{name}: NaN exactly where the argument is NaN")
    check(np.array_equal(got[[0, 2, 4]], clean), f"{name}: the other points as without the NaNs")
check(np.isnan(hairlut.furnace([0.1, 0.2], beta=float("nan"))["E"]).all(), "furnace: a NaN beta gives NaN")

# Tables as a renderer reads them, against the physics.
tables = hairlut.load_tables(h5)
rng = np.random.default_rng(7)
worst = 0.0
for lobe in ("R", "TT", "TRT"):
    c = tables[f"np/{lobe}"].coords
    for _ in range(6):
        beta = math.exp(rng.uniform(math.log(c["beta"][0]), math.log(c["beta"][-1])))
        sigma_a = rng.uniform(c["sigma_a"][0], c["sigma_a"][-1])
        theta_d = rng.uniform(c["theta_d"][0], c["theta_d"][-1])
        phi = np.linspace(0.0, math.pi, 61)
        table = tables.sample(f"np/{lobe}", beta=beta, sigma_a=sigma_a, theta_d=theta_d, phi=phi)
        direct = hairlut.azimuthal_np(lobe, phi, theta_d=theta_d, sigma_a=sigma_a, beta=beta)
        white_peak = hairlut.azimuthal_np(lobe, phi, theta_d=theta_d, sigma_a=0.0, beta=beta).max()
        worst = max(worst, np.max(np.abs(table - direct)) / max(direct.max(), 1e-3 * white_peak))
print(f"np tables against direct evaluation, worst relative to the slice peak: {worst:.3g}")
check(worst <= 2e-2, f"np tables read through TableSet.sample within 2e-2 of the slice peak (got {worst:.3g})")
c = tables["mp/R"].coords
theta_r = np.linspace(c["theta_r"][0], c["theta_r"][-1], 301)
mp_table = tables.sample("mp/R", beta=rad(10), theta_i=rad(30), theta_r=theta_r)
alpha = rad(-4)  # the default tables' tilt of R
mp_direct = hairlut.longitudinal_mp(rad(10), rad(30), theta_r, alpha=alpha)
mp_err = np.max(np.abs(mp_table - mp_direct)) / mp_direct.max()
print(f"mp/R against direct evaluation: {mp_err:.3g}")
check(mp_err <= 1e-2, f"mp/R read through TableSet.sample within 1e-2 of its peak (got {mp_err:.3g})")
check(np.isnan(tables.sample("mp/R", beta=rad(10), theta_i=np.nan, theta_r=0.0)), "TableSet.sample: NaN in, NaN out")

# A Fourier set: np_fourier/<lobe> holds coefficients over (theta_d, sigma_a, n); sample() reads N_p.
fourier = hairlut.load_tables(fourier_h5)
check(fourier.domain_dims("np_fourier/TT") == ("beta", "sigma_a", "theta_d", "phi"), "Fourier N_p sampled over (beta, sigma_a, theta_d, phi)")
check(fourier.domain_dims("np_fourier/residual") == ("sigma_a", "theta_d"), "the Fourier residual over (sigma_a, theta_d)")
f_worst = 0.0
for lobe in ("R", "TT", "TRT", "TRRT"):
    d = {a["name"]: a["range"] for a in fourier.domain(f"np_fourier/{lobe}")}
    for _ in range(4):
        beta = math.exp(rng.uniform(math.log(d["beta"][0]), math.log(d["beta"][1])))
        sigma_a, theta_d = rng.uniform(*d["sigma_a"]), rng.uniform(*d["theta_d"])
        phi = np.linspace(0.0, math.pi, 181)
        table = fourier.sample(f"np_fourier/{lobe}", beta=beta, sigma_a=sigma_a, theta_d=theta_d, phi=phi)
        direct = hairlut.azimuthal_np(lobe, phi, theta_d=theta_d, sigma_a=sigma_a, beta=beta)
        white_peak = hairlut.azimuthal_np(lobe, phi, theta_d=theta_d, sigma_a=0.0, beta=beta).max()
        f_worst = max(f_worst, np.max(np.abs(table - direct)) / max(direct.max(), 1e-3 * white_peak))
d = {a["name"]: a["range"] for a in fourier.domain("np_fourier/residual")}
sigma_a, theta_d = rng.uniform(*d["sigma_a"], 32), rng.uniform(*d["theta_d"], 32)
residual = fourier.sample("np_fourier/residual", sigma_a=sigma_a, theta_d=theta_d)
exact = hairlut.lobe_energies(theta_d, sigma_a, lobes=4, residual=True)[:, -1]
f_res = np.max(np.abs(residual * 2.0 * math.pi - exact) / np.maximum(exact, 1e-6))
print(f"Fourier N_p against direct evaluation, worst relative to the slice peak: {f_worst:.3g}; residual {f_res:.3g}")
check(f_worst <= 1e-3 and f_res <= 1e-3, f"Fourier tables read through TableSet.sample within 1e-3 (got {f_worst:.3g}, residual {f_res:.3g})")


def runtime_checks(hair, fiber, label, white):
    wo = np.array([[0.3, 0.9539392014169456, 0.0], [-0.6, 0.0, 0.8], [0.05, -0.7, -0.7124], [0.9, 0.3, -0.316227766]])
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    u = rng.random((len(wo), 200, 3))
    s = hair.sample(fiber, wo[:, None, :], u)
    ok = s["pdf"] > 0
    check(ok.mean() > 0.9, f"{label}: samples drawn")
    f = hair.eval(fiber, wo[:, None, :], s["wi"])
    check(np.allclose((s["weight"] * s["pdf"][..., None])[ok], f[ok], rtol=1e-5, atol=1e-12), f"{label}: weight x pdf = eval")
    check(np.allclose(hair.pdf(fiber, wo[:, None, :], s["wi"])[ok], s["pdf"][ok], rtol=1e-5), f"{label}: pdf() = the sample's pdf")
    if white:
        # Each weight is the albedo up to the linear interpolation of the lobe energies in the
        # theta_i density (hair_scattering.hpp, sampling stage 1), which the default tables'
        # accuracy_max_rel bounds: 1e-2.
        albedo = hair.albedo(fiber, wo)
        dev = np.max(np.abs(s["weight"][ok] - np.broadcast_to(albedo[:, None, None], s["weight"].shape)[ok]) / albedo.min())
        print(f"{label}: largest |weight - albedo| / albedo {dev:.3g}")
        check(dev <= 1e-2, f"{label}: a white fiber's weights are its albedo at wo within the energy tables' accuracy (got {dev:.3g})")
    check(np.isnan(hair.eval(fiber, [np.nan, 0.0, 1.0], wo[0])).all(), f"{label}: eval of a NaN direction is NaN")
    print(f"{label}: {ok.sum()} samples checked")


hair = tables.scattering()
runtime_checks(hair, hairlut.Fiber(sigma_a=[0.0, 0.0, 0.0], beta_m=0.2, beta_n=0.25), "generic tables, white fiber", True)
runtime_checks(hair, hairlut.fiber_from_melanin(0.8, 0.2, beta_m=0.2, beta_n=0.2), "generic tables, brown fiber", False)
prepared = hair.prepared(hairlut.Fiber(sigma_a=[0.0, 0.0, 0.0], beta_m=0.2, beta_n=0.25))
runtime_checks(prepared, hairlut.Fiber(sigma_a=[0.0, 0.0, 0.0], beta_m=0.2, beta_n=0.25), "generic tables prepared, white fiber", True)
runtime_checks(prepared, hairlut.fiber_from_melanin(0.8, 0.2, beta_m=0.2, beta_n=0.25), "generic tables prepared, brown fiber", False)
try:
    prepared.prepared(hairlut.Fiber(sigma_a=[0.0, 0.0, 0.0], beta_m=0.2, beta_n=0.25))
    check(False, "preparing a prepared runtime: nothing raised")
except hairlut.DomainError:
    pass
show = hairlut.bake(show_config, write=True, output_dir=work / "show")
material = [p for p in show if p.startswith("materials/")][0].split("/")[1]
runtime_checks(show.scattering(material), hairlut.Fiber(sigma_a=[0.0, 0.0, 0.0], beta_m=0.1, beta_n=0.1), f"material {material}", False)

if failures:
    print(f"{len(failures)} checks failed")
    sys.exit(1)
print("python runtime ok")
