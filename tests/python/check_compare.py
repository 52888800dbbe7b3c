#!/usr/bin/env python3
"""compare-hair-models output: compare.html is one self-contained page (inline SVG, no scripts, no
external resources) and compare.json holds the comparison's figures: polar N_p per lobe for
each model at several theta_d, energies per theta_i of every model, the cubic approximation's error
(Marschner's 0.75 degree claim for eta' >= 1.5 holds; it does not near eta' = 1.2) and the caustic."""
import json
import math
import re
import sys

d = sys.argv[1]
html = open(f"{d}/compare.html", encoding="utf-8").read()
c = json.load(open(f"{d}/compare.json"))
md = open(f"{d}/compare.md", encoding="utf-8").read()
assert "<script" not in html.lower(), "scripts are not allowed"
assert not re.findall(r'(?:src|href)\s*=\s*"([^"]*)"', html), "external references"
assert not [u for u in re.findall(r"https?://[^\"' )]+", html) if u != "http://www.w3.org/2000/svg"], "network references"
polar = c["polar"]
assert len(polar) >= 2
for e in polar:
    for lobe in ("R", "TT", "TRT", "total"):
        for model in ("deon_smooth", "deon_rough", "marschner_exact", "marschner_cubic"):
            v = e["lobes"][lobe][model]
            assert len(v) == len(e["phi_deg"]), (lobe, model)
            assert all(x is None or (math.isfinite(x) and x >= 0) for x in v), (lobe, model)
    # d'Eon's rough N_R integrates (over phi in [-pi, pi]) to its lobe energy.
    phi = [math.radians(x) for x in e["phi_deg"]]
    r = e["lobes"]["R"]["deon_rough"]
    integral = 2 * sum(0.5 * (r[i] + r[i + 1]) * (phi[i + 1] - phi[i]) for i in range(len(phi) - 1))
    assert abs(integral - e["energies"]["R"]["deon"]) < 2e-3 * e["energies"]["R"]["deon"], (integral, e["energies"]["R"])
sn = c["cubic"]["snell"]
assert sn["max_error_eta_prime_ge_1_5_deg"] < 0.75
assert sn["max_error_at_1_2_deg"] > 0.75
assert len(c["cubic"]["cases"]) >= 2
en = c["energy"]
n = len(en["theta_i_deg"])
for k in ("deon_R+TT+TRT", "deon_with_residual", "marschner_exact", "marschner_cubic", "kajiya_kay"):
    assert len(en[k]) == n and all(math.isfinite(x) and x >= 0 for x in en[k]), k
assert html.count("<svg") >= 4 * len(polar) + 5
assert md.startswith("# hairlut model comparison")
print(f"compare ok: {len(polar)} theta_d, {n} theta_i, cubic error {sn['max_error_eta_prime_ge_1_5_deg']:.3f} deg for eta' >= 1.5, "
      f"{html.count('<svg')} inline SVG plots")
