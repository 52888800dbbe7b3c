#!/usr/bin/env python3
"""The Python module's extension (hairlut._core) against hostile arguments.

Arguments: a baked HDF5 table file, a scratch directory. Complex arrays are refused (TypeError)
instead of losing their imaginary part; a path with an embedded NUL is refused (ValueError)
instead of naming a shorter, other file; beta below 1e-6 rad is refused (ValueError) instead of
returning NaN; long calls (azimuthal_np here, lobe_energies, furnace, dual_scattering and bake in
children) are interrupted by SIGINT (KeyboardInterrupt) long before they would finish.
"""
import os
import shutil
import signal
import subprocess
import sys
import threading
import time

import numpy as np

from hairlut import _core

TABLE, WORK = sys.argv[1:3]
os.makedirs(WORK, exist_ok=True)
failures = []


def expect(what, exc, f):
    try:
        f()
    except exc as e:
        print("ok  %s: %s: %s" % (what, type(e).__name__, str(e)[:120]))
        return
    except Exception as e:  # the wrong kind of error
        failures.append("%s: %s %s, expected %s" % (what, type(e).__name__, e, exc.__name__))
        return
    failures.append("%s: no error, expected %s" % (what, exc.__name__))


one = np.array([0.3])


def np_call(phi=one, theta_d=one, sigma_a=one, beta=one):
    return _core.azimuthal_np(1, phi, theta_d, sigma_a, beta, 1.55, "chord", "baker", 1e-10, 64, "h")


expect("complex phi", TypeError, lambda: np_call(phi=np.array([0.3 + 1j])))
expect("complex beta", TypeError, lambda: np_call(beta=np.array([0.3 + 0.5j])))
# The same through the public module, whose conversion to float64 would drop the imaginary part.
import hairlut  # noqa: E402

expect("public complex phi", TypeError, lambda: hairlut.azimuthal_np("TT", np.array([0.3 + 1j]), 0.3, 0.3, 0.3))
expect("public complex theta_i", TypeError, lambda: hairlut.longitudinal_mp(0.3, np.array([0.2 + 0.1j]), 0.1))
# Every argument of the public functions that takes a number: a complex value is refused in one
# line that names the argument (numpy's float64 conversion would drop the imaginary part).
z = np.array([0.3 + 1e-3j])
zs = np.complex128(1.55 + 0.1j)  # a numpy complex scalar: float() of it drops the imaginary part too
rows = np.array([[0.3, 0.9539392014169456, 0.0]])
public = [
    ("theta_d", lambda: hairlut.azimuthal_np("TT", 0.3, z, 0.3, 0.3)),
    ("sigma_a", lambda: hairlut.azimuthal_np("TT", 0.3, 0.3, z, 0.3)),
    ("beta", lambda: hairlut.azimuthal_np("TT", 0.3, 0.3, 0.3, z)),
    ("eta", lambda: hairlut.azimuthal_np("TT", 0.3, 0.3, 0.3, 0.3, eta=zs)),
    ("tolerance", lambda: hairlut.azimuthal_np("TT", 0.3, 0.3, 0.3, 0.3, method="adaptive", tolerance=np.complex128(1e-8 + 1e-9j))),
    ("order", lambda: hairlut.azimuthal_np("TT", 0.3, 0.3, 0.3, 0.3, method="gauss-legendre", order=np.complex128(64 + 1j))),
    ("lobe", lambda: hairlut.azimuthal_np(np.complex128(1 + 1j), 0.3, 0.3, 0.3, 0.3)),
    ("beta", lambda: hairlut.longitudinal_mp(z, 0.2, 0.1)),
    ("alpha", lambda: hairlut.longitudinal_mp(0.3, 0.2, 0.1, alpha=z)),
    ("theta_r", lambda: hairlut.longitudinal_mp(0.3, 0.2, z)),
    ("theta_d", lambda: hairlut.lobe_energies(z, 0.3)),
    ("sigma_a", lambda: hairlut.lobe_energies(0.3, z)),
    ("eta", lambda: hairlut.lobe_energies(0.3, 0.3, eta=zs)),
    ("theta_i", lambda: hairlut.furnace(z, beta=0.2)),
    ("beta", lambda: hairlut.furnace(0.3, beta=z)),
    ("alpha", lambda: hairlut.furnace(0.3, beta=0.2, alpha=[0.0, z[0], 0.0, 0.0])),
    ("sigma_a", lambda: hairlut.furnace(0.3, beta=0.2, sigma_a=zs)),
    ("theta_i", lambda: hairlut.dual_scattering(z, beta=0.2)),
    ("beta", lambda: hairlut.dual_scattering(0.3, beta=zs)),
    ("density_factor", lambda: hairlut.dual_scattering(0.3, beta=0.2, density_factor=zs)),
    ("eumelanin", lambda: hairlut.fiber_from_melanin(zs, 0.2, 0.2, 0.2)),
    ("beta_n", lambda: hairlut.fiber_from_melanin(0.8, 0.2, 0.2, zs)),
    ("sigma_a", lambda: hairlut.Fiber(sigma_a=[zs, 0.2, 0.1], beta_m=0.2, beta_n=0.2)),
    ("beta_m", lambda: hairlut.Fiber(sigma_a=[0.3, 0.2, 0.1], beta_m=zs, beta_n=0.2)),
    ("tilt", lambda: hairlut.Fiber(sigma_a=[0.3, 0.2, 0.1], beta_m=0.2, beta_n=0.2, tilt=np.complex64(0.1 + 1j))),
]
tables = hairlut.load_tables(TABLE)
hair = tables.scattering()
fiber = hairlut.fiber_from_melanin(0.8, 0.2, 0.2, 0.2)
public += [("wo", lambda: hair.eval(fiber, rows + 1e-3j, rows)), ("wi", lambda: hair.pdf(fiber, rows, rows + 1e-3j)),
           ("u", lambda: hair.sample(fiber, rows, np.full((1, 3), 0.5 + 0.1j))),
           ("theta_d", lambda: tables.sample("np/TT", beta=0.2, sigma_a=0.3, theta_d=z, phi=0.3))]
before = len(failures)
for name, f in public:
    try:
        f()
        failures.append("public complex %s: no error, expected TypeError" % name)
    except TypeError as e:
        if not str(e).startswith(name + ":") or "\n" in str(e):
            failures.append("public complex %s: the error does not name it in one line: %s" % (name, e))
    except Exception as e:
        failures.append("public complex %s: %s %s, expected TypeError" % (name, type(e).__name__, e))
if len(failures) == before:
    print("ok  %d complex arguments of the public functions refused, each named" % len(public))

expect("beta = 1e-300", ValueError, lambda: np_call(beta=np.array([1e-300])))
expect("beta = 0", ValueError, lambda: np_call(beta=np.array([0.0])))

# A NUL in a path: the C library would read the name up to the NUL (here, the real table).
copy = os.path.join(WORK, "t.h5")
shutil.copyfile(TABLE, copy)
expect("load_tables with a NUL in the path", ValueError, lambda: _core.load_tables(copy + "\0.txt"))
expect("load_config_file with a NUL in the path", ValueError, lambda: _core.load_config_file(copy + "\0.json"))
expect("Tables with a NUL in the path", ValueError, lambda: _core.Tables(copy + "\0.txt"))

# Ctrl-C: SIGINT from another thread after 0.5 s; the call (2e5 points, minutes) must stop soon.
n = 200000
phi = np.linspace(-3.0, 3.0, n)
timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
t0 = time.monotonic()
timer.start()
try:
    _core.azimuthal_np(1, phi, np.full(n, 0.3), np.full(n, 0.5), np.full(n, 0.2), 1.55, "chord", "adaptive", 1e-12, 64, "h")
    failures.append("azimuthal_np of %d points finished without seeing SIGINT" % n)
except KeyboardInterrupt:
    print("ok  azimuthal_np of %d points interrupted after %.2f s" % (n, time.monotonic() - t0))
finally:
    timer.cancel()

# Every other long call, each in a child started on an input that takes far longer than the test
# allows: SIGINT about 1 s into the call must end it with KeyboardInterrupt within a few seconds.
# A bake is interrupted while it writes nothing yet; it must leave no temporary behind.
CHILD = r"""
import os, sys, time
import numpy as np
import hairlut
what, work = sys.argv[1], sys.argv[2]
# Sizes that take minutes here (about 45 us, 28 ms and 180 ms a point); the bake, 31 s on one thread.
call = {
    "lobe_energies": lambda: hairlut.lobe_energies(np.linspace(0.0, 1.5, 4000000), 0.5, lobes=4, residual=True),
    "furnace": lambda: hairlut.furnace(np.linspace(-1.5, 1.5, 20000), beta=0.05, lobes=3, residual=True),
    "dual_scattering": lambda: hairlut.dual_scattering(np.linspace(-1.5, 1.5, 5000), beta=0.05, sigma_a=0.4),
    "bake": lambda: hairlut.bake({
        "name": "interrupted",
        "lobes": {"explicit": ["R", "TT", "TRT"], "residual": True},
        "quadrature": {"method": "fourier", "tolerance": 1e-12},
        "tables": {"np": {"axes": {"theta_d": {"count": 64, "range_deg": [0, 89]}, "phi": {"count": 128, "symmetry": "even"},
                                   "sigma_a": {"count": 16, "range": [0, 8]}, "beta": {"count": 32, "range_deg": [1, 30]}}}},
        "output": {"directory": os.path.join(work, "interrupted"), "basename": "i", "formats": ["hdf5"]},
    }, threads=1, write=True),
}[what]
print("calling", flush=True)
t0 = time.monotonic()
try:
    call()
    print("finished after %.2f s" % (time.monotonic() - t0), flush=True)
except KeyboardInterrupt:
    print("interrupted after %.2f s" % (time.monotonic() - t0), flush=True)
    sys.exit(3)
"""
LATENCY = 3.0  # seconds from SIGINT to the child's exit that a user at a prompt would accept
for what in ("lobe_energies", "furnace", "dual_scattering", "bake"):
    child = subprocess.Popen([sys.executable, "-c", CHILD, what, WORK], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = child.stdout.readline()  # printed just before the call
    if not line.startswith("calling"):
        child.kill()
        failures.append("%s: the child did not start: %s %s" % (what, line, child.communicate()[1][-300:]))
        continue
    time.sleep(1.0)
    child.send_signal(signal.SIGINT)
    sent = time.monotonic()
    try:
        out, err = child.communicate(timeout=LATENCY)
    except subprocess.TimeoutExpired:
        child.kill()
        child.communicate()
        failures.append("%s: still running %.0f s after SIGINT" % (what, LATENCY))
        continue
    took = time.monotonic() - sent
    if child.returncode == 3 and "interrupted" in out:
        print("ok  %s interrupted: exit %.2f s after SIGINT (%s)" % (what, took, out.strip()))
    else:
        failures.append("%s: exit %d after SIGINT, not a KeyboardInterrupt: %s %s" % (what, child.returncode, out.strip(), err.strip()[-300:]))
leftovers = [n for n in os.listdir(os.path.join(WORK, "interrupted"))] if os.path.isdir(os.path.join(WORK, "interrupted")) else []
if leftovers:
    failures.append("the interrupted bake left files: %s" % ", ".join(leftovers))

for f in failures:
    print("FAIL: " + f)
if failures:
    sys.exit(1)
print("python hostile ok")
