#!/usr/bin/env python3
"""The Python module's extension (hairlut._core) against hostile arguments.

Arguments: a baked HDF5 table file, a scratch directory. Complex arrays are refused (TypeError)
instead of losing their imaginary part; a path with an embedded NUL is refused (ValueError)
instead of naming a shorter, other file; beta below 1e-6 rad is refused (ValueError) instead of
returning NaN; a long azimuthal_np call is interrupted by SIGINT (KeyboardInterrupt) long before
it would finish.
"""
import os
import shutil
import signal
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
expect("beta = 1e-300", ValueError, lambda: np_call(beta=np.array([1e-300])))
expect("beta = 0", ValueError, lambda: np_call(beta=np.array([0.0])))

# A NUL in a path: the C library would read the name up to the NUL (here, the real table).
copy = os.path.join(WORK, "t.h5")
shutil.copyfile(TABLE, copy)
expect("load_tables with a NUL in the path", ValueError, lambda: _core.load_tables(copy + "\0.txt"))
expect("load_config_file with a NUL in the path", ValueError, lambda: _core.load_config_file(copy + "\0.json"))

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

for f in failures:
    print("FAIL: " + f)
if failures:
    sys.exit(1)
print("python hostile ok")
