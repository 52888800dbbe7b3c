#!/usr/bin/env python3
"""Independent worst-point search over baked hairlut tables: a search by other means than the
validator's should find nothing worse than 1.5x what the validator reports for the same file.

What it checks. Every N_p table (np/R, TT, TRT, TRRT, or their Fourier series np_fourier/*), every
energy table (np/energy_*, and the residual np/residual or np_fourier/residual) and every M_p table
(mp/*) of a file, read as a renderer reads it (TableSet.sample: each axis's mapping and
interpolation, N_p as shape x energy; a Fourier table's series over the domain it stands for,
TableSet.domain), against direct
evaluation (hairlut.azimuthal_np, lobe_energies, longitudinal_mp) over each table's whole declared
domain. The error is the validator's measure (the 'denominator' of each table in report.json),
recomputed here by this script's own code:
  - N_p: |table - exact| / max(P, 1e-3 P0), P the peak over phi in [0, pi] of the exact slice at
    the same (beta, sigma_a, theta_d), P0 that peak for sigma_a = 0;
  - M_p: |table - exact| / (peak over theta_r in [-pi/2, pi/2] of the exact M_p at (beta, theta_i));
  - energies: |table - exact| / max(|exact|, 1e-3 |exact at sigma_a = 0|, 1e-6).
Peaks are found on a grid of three points per cell of the table's own axis, then refined by golden
section around the three highest local maxima. It prints, per table, the validator's worst (from
report.json), the worst found here, where, their ratio and the points each strategy compared; it
exits 1 when a ratio exceeds 1.5.

Why the strategies differ from the validator's. The validator draws seeded uniform random points,
then the first and last cells and the corners, the caustics and grazing ends, and hill-climbs from
its worst. This script draws no isolated random points and looks for no named features. A table's
last axis (phi, theta_r, theta_d) is scanned densely in every slice it touches (the slice's peak
comes from the same scan), and the slices come from
  1. lines: dense scans along each other axis in turn (three stratified-jittered positions in
     every cell, both ends included), through a random point or through a random cell's midpoint
     of the remaining axes;
  2. midcells: a sweep, in seeded random order, of the lattice of cell midpoints of those axes;
  3. nelder-mead: this file's own bounded Nelder-Mead over those axes (the error maximised over the
     last axis inside each evaluation), started from the worst slices of 1 and 2 and from random
     starts in turn.
The time budget is shared by table kind (N_p x4, energy x1, M_p x0.5, by the cost of exact
evaluation) and, within a table, 40% / 30% / 30% between the strategies; a strategy that runs out
of work leaves its time to the next.

Usage: independent_search.py --tables FILE.h5 --report report.json [--budget-seconds N] [--seed S] [--json OUT]
"""
import argparse
import json
import math
import re
import sys
import time
import zlib

import numpy as np

import hairlut

GOLD = (math.sqrt(5.0) - 1.0) / 2.0
RATIO_LIMIT = 1.5
KIND_WEIGHT = {"np": 4.0, "mp": 0.5, "energy": 1.0}
SHARES = (("lines", 0.4), ("midcells", 0.3), ("nelder-mead", 0.3))
PEAK_ITERATIONS, ERROR_ITERATIONS, CANDIDATES = 18, 14, 3
LINE_CHUNK, MIDCELL_CHUNK = 48, 32
DIMS = {("beta", "sigma_a", "theta_d", "phi"): "np", ("beta", "theta_i", "theta_r"): "mp", ("sigma_a", "theta_d"): "energy"}


class Axis:
    """One axis: its declared range and spacing, mapped to u in [0, 1] (the shipped spacings make
    the cells equal in u), and its nodes in u."""

    def __init__(self, desc, nodes):
        self.name, self.units, self.spacing = desc["name"], desc["units"], desc.get("spacing", "uniform")
        self.lo, self.hi = (float(v) for v in desc["range"])
        if self.spacing not in ("uniform", "log", "sqrt", "cos"):
            raise SystemExit(f"independent_search: axis {self.name}: unknown spacing {self.spacing!r}")
        self.nodes_u = self.to_u(np.asarray(nodes, dtype=float))

    def _map(self, x):
        if self.spacing == "log":
            return np.log(x)
        if self.spacing == "cos":
            return -np.cos(x)
        return np.sqrt(np.maximum(x - self.lo, 0.0)) if self.spacing == "sqrt" else x

    def to_u(self, x):
        m_lo, m_hi = self._map(self.lo), self._map(self.hi)
        return (self._map(x) - m_lo) / (m_hi - m_lo)

    def to_x(self, u):
        m_lo, m_hi = self._map(self.lo), self._map(self.hi)
        m = m_lo + np.clip(u, 0.0, 1.0) * (m_hi - m_lo)
        if self.spacing == "log":
            return np.clip(np.exp(m), self.lo, self.hi)
        if self.spacing == "cos":
            return np.clip(np.arccos(np.clip(-m, -1.0, 1.0)), self.lo, self.hi)
        return self.lo + m * m if self.spacing == "sqrt" else m

    def at_fractions(self, fractions):
        """u at the given fractions (one row per cell, or one row for every cell) of every cell."""
        a, w = self.nodes_u[:-1, None], np.diff(self.nodes_u)[:, None]
        return (a + w * np.asarray(fractions)).ravel()

    def cell(self, u):
        return np.clip(np.searchsorted(self.nodes_u, u, side="right") - 1, 0, len(self.nodes_u) - 2)

    def show(self, x):
        return f"{math.degrees(x):.4g} deg" if self.units == "rad" else f"{x:.4g}"


def golden_max(f, a, b, iterations):
    """Maximises f on [a, b], bracket by bracket (arrays), by golden section: (x, f(x))."""
    c, d = b - GOLD * (b - a), a + GOLD * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iterations):
        left = fc >= fd
        a, b = np.where(left, a, c), np.where(left, d, b)
        x = np.where(left, b - GOLD * (b - a), a + GOLD * (b - a))
        fx = f(x)
        c, fc, d, fd = np.where(left, x, d), np.where(left, fx, fd), np.where(left, c, x), np.where(left, fc, fx)
    return np.where(fc >= fd, c, d), np.maximum(fc, fd)


def brackets(values, grid):
    """Per row, the [u, u] brackets (grid neighbours) of the CANDIDATES highest local maxima."""
    padded = np.pad(values, ((0, 0), (1, 1)), constant_values=-np.inf)
    peak = (values >= padded[:, :-2]) & (values >= padded[:, 2:])
    top = np.argsort(-np.where(peak, values, -np.inf), axis=1)[:, :CANDIDATES]
    last = len(grid) - 1
    return grid[np.maximum(top - 1, 0)], grid[np.minimum(top + 1, last)]


class Target:
    """One table, its exact counterpart and the error measure; keeps the worst point found."""

    def __init__(self, tables, path):
        table, meta = tables[path], tables.metadata
        self.tables, self.path = tables, path
        self.axes = [Axis(a, a["values"]) for a in tables.domain(path)]
        self.dims = tuple(a.name for a in self.axes)
        self.kind = DIMS[self.dims]
        self.outer, self.inner = self.axes[:-1], self.axes[-1]
        self.inner_u = np.append(self.inner.at_fractions(np.arange(3) / 3.0), 1.0)
        attrs = table.description.get("attributes", {})
        self.lobe, self.alpha = attrs.get("lobe"), float(attrs.get("alpha", 0.0))
        self.eta, self.absorption_path = float(meta.get("eta", 1.55)), meta.get("absorption_path", "chord")
        lobes = list(meta.get("lobes", ["R", "TT", "TRT", "TRRT"]))
        self.n_lobes = int(meta.get("residual_from_p", len(lobes)))
        self.column = self.n_lobes if self.lobe == "residual" else (lobes.index(self.lobe) if self.lobe in lobes else None)
        # np/residual and np_fourier/residual: N of the residual, its energy / 2 pi.
        self.scale = 1.0 / (2.0 * math.pi) if table.quantity == "N_p" or table.group == "np_fourier" else 1.0
        self.peaks = {}
        self.points = {name: 0 for name, _ in SHARES}
        self.exact_evaluations = 0
        self.worst = {"rel": -1.0}
        self.slices = []  # (rel, outer u) of every slice scanned by lines and midcells

    def exact(self, x):
        self.exact_evaluations += len(x)
        if self.kind == "np":
            return hairlut.azimuthal_np(self.lobe, x[:, 3], x[:, 2], x[:, 1], x[:, 0], eta=self.eta, path=self.absorption_path)
        if self.kind == "mp":
            return hairlut.longitudinal_mp(x[:, 0], x[:, 1], x[:, 2], alpha=self.alpha)
        e = hairlut.lobe_energies(x[:, 1], x[:, 0], eta=self.eta, lobes=self.n_lobes, residual=True, path=self.absorption_path)
        return e[:, self.column] * self.scale

    def sampled(self, x):
        return self.tables.sample(self.path, **{d: x[:, i] for i, d in enumerate(self.dims)})

    def points_at(self, s, u_inner):
        """Physical points of slices s (outer x, one row each) at inner u (same shape rows)."""
        s = np.repeat(s, u_inner.shape[1], axis=0)
        return np.column_stack([s, self.inner.to_x(u_inner.ravel())])

    def slice_peaks(self, s, grid_values=None):
        """Peak of the exact function along the inner axis per slice (cached); grid_values, when
        given, are the exact values on self.inner_u already computed for these slices."""
        keys = [tuple(row) for row in s]
        todo = [i for i, k in enumerate(keys) if k not in self.peaks]
        if todo:
            sub = s[todo]
            grid = np.broadcast_to(self.inner_u, (len(sub), len(self.inner_u)))
            values = grid_values[todo] if grid_values is not None else self.exact(self.points_at(sub, grid)).reshape(grid.shape)
            a, b = brackets(values, self.inner_u)
            rows = np.repeat(sub, CANDIDATES, axis=0)
            _, refined = golden_max(lambda u: self.exact(np.column_stack([rows, self.inner.to_x(u)])),
                                    a.ravel(), b.ravel(), PEAK_ITERATIONS)
            best = np.maximum(values.max(axis=1), refined.reshape(-1, CANDIDATES).max(axis=1))
            for i, p in zip(todo, best):
                self.peaks[keys[i]] = float(p)
        return np.array([self.peaks[k] for k in keys])

    def slice_denominators(self, s, grid_values):
        if self.kind == "mp":
            return self.slice_peaks(s, grid_values)
        white = s.copy()
        white[:, 1] = 0.0
        return np.maximum(self.slice_peaks(s, grid_values), 1e-3 * self.slice_peaks(white))

    def relative(self, x, denominator):
        """(rel, sampled, exact, denominator) at points x; denominator per point for N_p and M_p
        (that of its slice); None for energies, whose denominator is pointwise."""
        e, t = self.exact(x), self.sampled(x)
        if denominator is None:
            white = x.copy()
            white[:, 0] = 0.0
            denominator = np.maximum(np.maximum(np.abs(e), 1e-3 * np.abs(self.exact(white))), 1e-6)
        return np.abs(t - e) / denominator, t, e, denominator

    def scan(self, s_u, strategy):
        """Scans slices (outer u, one row each) along the inner axis; returns each slice's worst."""
        s = np.column_stack([a.to_x(s_u[:, i]) for i, a in enumerate(self.outer)])
        grid = np.broadcast_to(self.inner_u, (len(s), len(self.inner_u)))
        x = self.points_at(s, grid)
        if self.kind == "energy":
            rel = self.relative(x, None)[0].reshape(grid.shape)
            den_rows = None
        else:
            e = self.exact(x).reshape(grid.shape)
            den_rows = self.slice_denominators(s, e)
            rel = np.abs(self.sampled(x).reshape(grid.shape) - e) / den_rows[:, None]
        a, b = brackets(rel, self.inner_u)
        rows = np.repeat(s, CANDIDATES, axis=0)
        den = None if den_rows is None else np.repeat(den_rows, CANDIDATES)
        u_ref, rel_ref = golden_max(lambda u: self.relative(np.column_stack([rows, self.inner.to_x(u)]), den)[0],
                                    a.ravel(), b.ravel(), ERROR_ITERATIONS)
        self.points[strategy] += rel.size + len(rows) * (2 + ERROR_ITERATIONS)
        u_ref, rel_ref = u_ref.reshape(-1, CANDIDATES), rel_ref.reshape(-1, CANDIDATES)
        j = np.argmax(rel_ref, axis=1)
        rows_i = np.arange(len(s))
        best_rel, best_u = rel_ref[rows_i, j], u_ref[rows_i, j]
        grid_j = np.argmax(rel, axis=1)
        on_grid = rel[rows_i, grid_j] > best_rel
        best_rel = np.where(on_grid, rel[rows_i, grid_j], best_rel)
        best_u = np.where(on_grid, self.inner_u[grid_j], best_u)
        k = int(np.argmax(best_rel))
        if best_rel[k] > self.worst["rel"]:
            self.record(s[k], best_u[k], None if den_rows is None else den_rows[k:k + 1], strategy)
        return best_rel

    def record(self, s_row, u_inner, den, strategy):
        x = np.append(s_row, self.inner.to_x(u_inner))[None, :]
        rel, t, e, d = self.relative(x, den)
        self.worst = {"rel": float(rel[0]), "x": x[0].tolist(), "sampled": float(t[0]), "exact": float(e[0]),
                      "denominator": float(np.ravel(d)[0]), "strategy": strategy}

    def where(self):
        return ", ".join(f"{a.name} = {a.show(v)}" for a, v in zip(self.axes, self.worst["x"]))

    def at(self):
        return {a.name: (math.degrees(v) if a.units == "rad" else v) for a, v in zip(self.axes, self.worst["x"])}


def lines(target, rng, deadline):
    """Dense scans along each outer axis in turn, through random points and random cells' midpoints."""
    n = 0
    while time.monotonic() < deadline:
        axis = n % len(target.outer)
        base = rng.random(len(target.outer))
        if (n // len(target.outer)) % 2:
            base = np.array([a.at_fractions([0.5])[a.cell(u)] for a, u in zip(target.outer, base)])
        jitter = (np.arange(3) + rng.random()) / 3.0
        along = np.concatenate([[0.0], target.outer[axis].at_fractions(jitter), [1.0]])
        s_u = np.tile(base, (len(along), 1))
        s_u[:, axis] = along
        for chunk in range(0, len(s_u), LINE_CHUNK):
            if time.monotonic() >= deadline:
                break
            part = s_u[chunk:chunk + LINE_CHUNK]
            target.slices.extend(zip(target.scan(part, "lines"), part))
        n += 1
    return {"lines_started": n}


def midcells(target, rng, deadline):
    """The lattice of outer cell midpoints, in seeded random order, as long as time allows."""
    mids = [a.at_fractions([0.5]) for a in target.outer]
    total = int(np.prod([len(m) for m in mids]))
    order = rng.permutation(total)
    done = 0
    while done < total and time.monotonic() < deadline:
        idx = np.unravel_index(order[done:done + MIDCELL_CHUNK], [len(m) for m in mids])
        s_u = np.column_stack([m[i] for m, i in zip(mids, idx)])
        target.slices.extend(zip(target.scan(s_u, "midcells"), s_u))
        done += len(s_u)
    return {"midcells_covered": done, "midcells_total": total}


def nelder_mead(f, x0, step, deadline, max_evaluations):
    """Minimises f over [0, 1]^k (points clipped into the box) from x0 with initial steps `step`."""
    k = len(x0)
    simplex = [np.clip(x0, 0, 1)]
    for i in range(k):
        e = np.zeros(k)
        e[i] = step[i] if x0[i] + step[i] <= 1.0 else -step[i]
        simplex.append(np.clip(x0 + e, 0, 1))
    values = [f(p) for p in simplex]
    evaluations = k + 1
    while evaluations < max_evaluations and time.monotonic() < deadline:
        order = np.argsort(values)
        simplex, values = [simplex[i] for i in order], [values[i] for i in order]
        if np.max(np.abs(np.array(simplex[1:]) - simplex[0])) < 1e-7:
            break
        centroid = np.mean(simplex[:-1], axis=0)
        reflected = np.clip(2 * centroid - simplex[-1], 0, 1)
        fr = f(reflected)
        evaluations += 1
        if fr < values[0]:
            expanded = np.clip(3 * centroid - 2 * simplex[-1], 0, 1)
            fe = f(expanded)
            evaluations += 1
            simplex[-1], values[-1] = (expanded, fe) if fe < fr else (reflected, fr)
        elif fr < values[-2]:
            simplex[-1], values[-1] = reflected, fr
        else:
            contracted = np.clip(0.5 * (centroid + simplex[-1]), 0, 1)
            fc = f(contracted)
            evaluations += 1
            if fc < values[-1]:
                simplex[-1], values[-1] = contracted, fc
            else:
                simplex = [simplex[0]] + [np.clip(0.5 * (simplex[0] + p), 0, 1) for p in simplex[1:]]
                values = [values[0]] + [f(p) for p in simplex[1:]]
                evaluations += k


def nelder_mead_starts(target, rng, deadline):
    """Nelder-Mead from the worst slices of lines and midcells (one per outer cell), and from
    random starts, alternately (two worst, one random)."""
    ranked = sorted(target.slices, key=lambda r: -r[0])
    seen, worst = set(), []
    for _, u in ranked:
        cell = tuple(int(a.cell(v)) for a, v in zip(target.outer, u))
        if cell not in seen:
            seen.add(cell)
            worst.append(u)
    starts = 0
    while time.monotonic() < deadline:
        x0 = worst.pop(0) if worst and starts % 3 != 2 else rng.random(len(target.outer))
        step = np.array([0.25 * np.diff(a.nodes_u)[a.cell(v)] for a, v in zip(target.outer, x0)])
        nelder_mead(lambda u: -target.scan(u[None, :], "nelder-mead")[0], x0, step, deadline, 40 * (len(x0) + 1))
        starts += 1
    return {"nelder_mead_starts": starts}


def search(target, seed, seconds):
    rng = np.random.default_rng([seed, zlib.crc32(target.path.encode())])
    start = time.monotonic()
    info, end = {}, start
    for (name, share), run in zip(SHARES, (lines, midcells, nelder_mead_starts)):
        end += share * seconds
        info.update(run(target, rng, end))
    info["seconds"] = round(time.monotonic() - start, 1)
    return info


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tables", required=True, help="the HDF5 (or EXR) table file")
    parser.add_argument("--report", required=True, help="the validator's report.json for that file")
    parser.add_argument("--budget-seconds", type=float, default=600.0, help="time for all tables together (default 600)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--json", help="write the results here too")
    parser.add_argument("--only", help="search only the tables whose path matches this regular expression")
    args = parser.parse_args()

    tables = hairlut.load_tables(args.tables)
    with open(args.report) as f:
        validator = {a["path"]: a for a in json.load(f)["accuracy"]}
    paths = [p for p in validator if p in tables and tables.domain_dims(p) in DIMS and (not args.only or re.search(args.only, p))]
    skipped = [p for p in validator if p not in paths and (not args.only or re.search(args.only, p))]
    targets = [Target(tables, p) for p in paths]
    weight = sum(KIND_WEIGHT[t.kind] for t in targets)
    results, failed = [], []
    for t in targets:
        info = search(t, args.seed, args.budget_seconds * KIND_WEIGHT[t.kind] / weight)
        v = validator[t.path]["worst"]
        ratio = t.worst["rel"] / v["max_rel"] if v["max_rel"] > 0 else math.inf
        if ratio > RATIO_LIMIT:
            failed.append(t.path)
        results.append({"path": t.path, "kind": t.kind, "denominator": validator[t.path]["denominator"],
                        "validator": {"worst": v["max_rel"], "where": v["where"]},
                        "independent": dict(t.worst, at=t.at(), where=t.where()), "ratio": ratio,
                        "points": t.points, "exact_evaluations": t.exact_evaluations, **info})
        print(f"{t.path}: validator {v['max_rel']:.3e} at {v['where']}\n"
              f"    independent {t.worst['rel']:.3e} ({t.worst['strategy']}) at {t.where()}\n"
              f"    ratio {ratio:.3f}; points compared: lines {t.points['lines']} ({info['lines_started']} lines), "
              f"midcells {t.points['midcells']} ({info['midcells_covered']}/{info['midcells_total']} cells), "
              f"nelder-mead {t.points['nelder-mead']} ({info['nelder_mead_starts']} starts); "
              f"exact evaluations {t.exact_evaluations}; {info['seconds']} s", flush=True)
    if skipped:
        print("not searched (this script has no exact counterpart for them): " + ", ".join(skipped))
    print(f"worst ratio {max(r['ratio'] for r in results):.3f} (limit {RATIO_LIMIT}): " +
          (f"FAIL: {', '.join(failed)}" if failed else "pass"))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"tables": args.tables, "report": args.report, "seed": args.seed, "budget_seconds": args.budget_seconds,
                       "ratio_limit": RATIO_LIMIT, "results": results, "not_searched": skipped, "failed": failed}, f, indent=1)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
