#!/usr/bin/env python3
"""hairlut-eval np prints by default the value the baker would store, and says which method made
each value. Checked against two independent evaluations: the adaptive reference (Gauss-Kronrod
between detector breakpoints) and, for a nearly smooth fiber, the smooth-fiber limit by root
solving.

  - TT at beta = 0.72 deg around its peak (where 64-point Gauss-Legendre is far off): the default
    value within 1e-10 of the lobe peak of the adaptive reference (the baker promises 1e-12 of
    the peak; the rest is headroom for the reference's own error and rounding).
  - TT at beta = 1e-6 rad, phi = 180 deg: no table can be baked at that beta; the default says so
    and prints the adaptive reference, which must match the smooth-fiber limit to 1e-9 relative
    (the detector of width 1e-6 changes N by O(beta^2)).
  - The fixed-order and the adaptive evaluations are reachable as options and named as such.
"""
import json
import math
import subprocess
import sys

EVAL = sys.argv[1]
failures = []


def run(*args):
    out = subprocess.run([EVAL, "--json", "np", *map(str, args)], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


narrow = ["--lobe", "TT", "--beta-deg", 0.72, "--theta-d-deg", 20, "--sigma-a", 0.5]
rows = []
for phi in [150, 160, 165, 170, 175, 178, 180]:
    d = run(*narrow, "--phi-deg", phi, "--reference")
    if "baker" not in d["method"]:
        failures.append(f"TT 0.72 deg phi {phi}: default method is '{d['method']}', not the baker's")
    rows.append((phi, d["N"], d["N_reference"], d["N_reference_converged"]))
peak = max(r[2] for r in rows)
worst = 0.0
for phi, n, ref, converged in rows:
    worst = max(worst, abs(n - ref) / peak)
    if not converged:
        failures.append(f"TT 0.72 deg phi {phi}: the adaptive reference did not converge")
    if abs(n - ref) > 1e-10 * peak:
        failures.append(f"TT 0.72 deg phi {phi}: default N {n!r} vs adaptive reference {ref!r} (peak {peak})")
gl = run(*narrow, "--phi-deg", 180, "--method", "gauss-legendre", "--order", 64)
if "fixed-order Gauss-Legendre, 64 nodes" not in gl["method"]:
    failures.append(f"--method gauss-legendre is described as '{gl['method']}'")
ad = run(*narrow, "--phi-deg", 180, "--method", "adaptive")
if not ad["method"].startswith("adaptive reference") or "N_error" not in ad:
    failures.append(f"--method adaptive is described as '{ad['method']}' without its error estimate")

tiny = ["--lobe", "TT", "--beta-deg", math.degrees(1e-6), "--theta-d-deg", 20, "--sigma-a", 0.5, "--phi-deg", 180]
d = run(*tiny, "--smooth")
if "cannot bake" not in d.get("note", "") or not d["method"].startswith("adaptive reference"):
    failures.append(f"beta 1e-6 rad: method '{d['method']}', note '{d.get('note')}'")
rel = abs(d["N"] - d["N_smooth_fiber"]) / d["N_smooth_fiber"]
if not rel <= 1e-9:
    failures.append(f"beta 1e-6 rad: N {d['N']!r} vs smooth-fiber limit {d['N_smooth_fiber']!r} (relative {rel:.3g})")

if failures:
    print("\n".join(failures))
    sys.exit(1)
print(f"eval np ok: TT 0.72 deg default within {worst:.2g} of the peak of the adaptive reference "
      f"(64-point Gauss-Legendre at 180 deg: {gl['N']:.6g} vs {rows[-1][2]:.6g}); "
      f"beta 1e-6 rad: {d['N']:.12g} vs smooth fiber {d['N_smooth_fiber']:.12g} (relative {rel:.2g})")
