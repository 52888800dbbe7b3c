"""hairlut from Python: d'Eon 2011 hair scattering functions, baking and baked tables.

Angles are radians, as in the C++ library (numpy.radians converts degrees). Evaluation
functions broadcast their array arguments like numpy ufuncs and return arrays of the broadcast
shape; a NaN argument gives NaN where it falls. Errors in arguments raise hairlut.DomainError or
hairlut.ConfigError (both ValueError); unreadable files raise hairlut.IoError (an OSError).

    import numpy as np, hairlut
    phi = np.linspace(0, np.pi, 181)
    n = hairlut.azimuthal_np("TRT", phi, theta_d=np.radians(20), sigma_a=0.5, beta=np.radians(5))
    tables = hairlut.load_tables("tables/default/hairlut-default.h5")
    trt = tables["np/TRT"]          # .values (numpy), .dims, .coords {axis: node coordinates}
    da = trt.to_xarray()             # when xarray is installed
    hair = tables.scattering()       # the C++ renderer runtime over the tables: eval, sample, pdf
"""

import json
import os
from dataclasses import dataclass, field

import numpy

from . import _core
from ._core import ConfigError, DomainError, Fiber, IoError

__version__ = _core.version
__all__ = ["longitudinal_mp", "azimuthal_np", "lobe_energies", "furnace", "dual_scattering", "bake", "load_tables",
           "fiber_from_melanin", "Fiber", "Scattering", "Table", "TableSet", "ConfigError", "DomainError", "IoError", "__version__"]


def _real(a, name):
    """a as float64, refusing complex input (numpy's conversion would drop the imaginary part with
    only a ComplexWarning) in one line that names the argument."""
    if numpy.iscomplexobj(a):
        raise TypeError(f"{name}: complex values are refused (hairlut takes real angles and coefficients; the imaginary part would be dropped)")
    return numpy.asarray(a, dtype=numpy.float64)


def _scalar(v, name):
    """One real number (float() of a numpy complex drops the imaginary part too)."""
    a = _real(v, name)
    if a.ndim != 0 and a.size != 1:
        raise TypeError(f"{name} must be one number, got shape {a.shape}")
    return float(a.reshape(()))


def _integer(v, name):
    if numpy.iscomplexobj(v):
        raise TypeError(f"{name}: complex values are refused (an integer is expected)")
    return int(v)


def _lobe(p):
    return _core.parse_lobe(p) if isinstance(p, str) else _integer(p, "lobe")


def _broadcast(**args):
    """The arguments (by name, in order) as float64, broadcast and flattened."""
    arrays = numpy.broadcast_arrays(*[_real(a, name) for name, a in args.items()])
    shape = arrays[0].shape
    return shape, [numpy.ascontiguousarray(a).reshape(-1) for a in arrays]


def _nan_rows(flat):
    """Where any of the flat argument arrays is NaN (those points give NaN, uncomputed)."""
    nan = numpy.zeros(flat[0].shape, dtype=bool)
    for a in flat:
        nan |= numpy.isnan(a)
    return nan


def _finite_scalars(**values):
    return not any(numpy.isnan(_real(v, name)).any() for name, v in values.items())


def longitudinal_mp(beta, theta_i, theta_r, alpha=0.0):
    """d'Eon 2011's M_p (eq. 7, v = beta^2) with cuticle tilt alpha shifting the cone in theta_r."""
    shape, flat = _broadcast(beta=beta, alpha=alpha, theta_i=theta_i, theta_r=theta_r)
    nan = _nan_rows(flat)
    out = numpy.full(nan.shape, numpy.nan)
    if not nan.all():
        out[~nan] = _core.longitudinal_mp(*[a[~nan] for a in flat])
    return out.reshape(shape)


def azimuthal_np(lobe, phi, theta_d, sigma_a, beta, eta=1.55, path="chord", method="baker", tolerance=1e-12, order=64,
                 variable="gamma", return_error=False):
    """N_p(phi) of one lobe ("R", "TT", "TRT", ... or p).

    method "baker" (default): the baker's Fourier/spreading quadrature with `tolerance` relative to
    the lobe peak -- the value a table stores (the adaptive reference where the baker cannot bake
    so narrow a beta). "adaptive": the adaptive reference with `tolerance` relative to the value;
    with return_error=True its error estimate is returned too. "gauss-legendre": a fixed rule of
    `order` nodes in `variable` ("gamma" or "h"), not adaptive, so it misses narrow lobes.
    Each point is evaluated on its own: the baker's method costs about as much per point as per
    table row, more the narrower beta is; bake() is the fast way to fill a grid.
    """
    shape, flat = _broadcast(phi=phi, theta_d=theta_d, sigma_a=sigma_a, beta=beta)
    eta, tolerance, order = _scalar(eta, "eta"), _scalar(tolerance, "tolerance"), _integer(order, "order")
    nan = _nan_rows(flat) | numpy.isnan(eta)
    value, error = numpy.full(nan.shape, numpy.nan), numpy.full(nan.shape, numpy.nan)
    if not nan.all():
        v, e = _core.azimuthal_np(_lobe(lobe), *[a[~nan] for a in flat], eta, path, method, tolerance, order, variable)
        value[~nan], error[~nan] = v, e
    if return_error:
        return value.reshape(shape), error.reshape(shape)
    return value.reshape(shape)


def lobe_energies(theta_d, sigma_a, eta=1.55, lobes=4, residual=False, path="chord"):
    """Per-lobe energies 1/2 int A(p, h) dh (adaptive reference): shape broadcast + (lobes [+ 1],)."""
    shape, flat = _broadcast(theta_d=theta_d, sigma_a=sigma_a)
    eta, lobes = _scalar(eta, "eta"), _integer(lobes, "lobes")
    nan = _nan_rows(flat) | numpy.isnan(eta)
    out = numpy.full(nan.shape + (lobes + (1 if residual else 0),), numpy.nan)
    if not nan.all():
        out[~nan] = _core.lobe_energies(*[a[~nan] for a in flat], eta, path, lobes, bool(residual))
    return out.reshape(shape + (out.shape[1],))


def _per_lobe(values, name):
    return [float(v) for v in numpy.atleast_1d(_real(values, name))]


def furnace(theta_i, beta, alpha=0.0, lobes=3, residual=True, eta=1.55, sigma_a=0.0, path="chord"):
    """Directional albedo E(theta_i) of the full model (the white furnace for sigma_a = 0).

    beta and alpha: one value for every lobe, or one per lobe (and the residual), radians, with
    beta_m = beta_n. Returns {"E": shape of theta_i, "per_lobe": shape + (lobes,), "converged"}.
    """
    ti = _real(theta_i, "theta_i")
    flat = ti.reshape(-1)
    eta, sigma_a, lobes = _scalar(eta, "eta"), _scalar(sigma_a, "sigma_a"), _integer(lobes, "lobes")
    nan = numpy.isnan(flat) | (not _finite_scalars(eta=eta, sigma_a=sigma_a, beta=beta, alpha=alpha))
    E, per_lobe = numpy.full(flat.shape, numpy.nan), numpy.full(flat.shape + (lobes + (1 if residual else 0),), numpy.nan)
    converged = numpy.zeros(flat.shape, dtype=bool)
    if not nan.all():
        r = _core.furnace(flat[~nan], eta, sigma_a, path, _per_lobe(beta, "beta"), _per_lobe(alpha, "alpha"), lobes, bool(residual))
        E[~nan], per_lobe[~nan], converged[~nan] = r["E"], r["per_lobe"], numpy.array(r["converged"])
    return {"E": E.reshape(ti.shape), "per_lobe": per_lobe.reshape(ti.shape + (per_lobe.shape[1],)), "converged": converged.reshape(ti.shape)}


_DUAL_KEYS = ("E", "a_f", "a_b", "alpha_f", "alpha_b", "beta_f2", "beta_b2", "A_b", "delta_b", "sigma_b")


def dual_scattering(theta_i, beta, alpha=0.0, lobes=3, residual=True, eta=1.55, sigma_a=0.0, path="chord", density_factor=0.7):
    """Mean energy and Zinke 2008's dual-scattering quantities at each theta_i (arrays of its shape):
    E, a_f, a_b, alpha_f, alpha_b (rad), beta_f2, beta_b2 (rad^2), A_b, delta_b, sigma_b, converged."""
    ti = _real(theta_i, "theta_i")
    flat = ti.reshape(-1)
    eta, sigma_a, density_factor = _scalar(eta, "eta"), _scalar(sigma_a, "sigma_a"), _scalar(density_factor, "density_factor")
    lobes = _integer(lobes, "lobes")
    nan = numpy.isnan(flat) | (not _finite_scalars(eta=eta, sigma_a=sigma_a, beta=beta, alpha=alpha, density_factor=density_factor))
    r = {}
    if not nan.all():
        r = _core.dual_scattering(flat[~nan], eta, sigma_a, path, _per_lobe(beta, "beta"), _per_lobe(alpha, "alpha"), lobes, bool(residual),
                                  density_factor)
    else:
        r = {k: numpy.zeros(0) for k in _DUAL_KEYS}
        r["converged"] = numpy.zeros(0, dtype=bool)
    out = {}
    for k, v in r.items():
        v = numpy.asarray(v)
        full = numpy.zeros(flat.shape, dtype=bool) if v.dtype == bool else numpy.full(flat.shape, numpy.nan)
        full[~nan] = v
        out[k] = full.reshape(ti.shape)
    return out


@dataclass
class Table:
    """One baked table: values over named axes (last axis fastest) with node coordinates."""
    path: str
    group: str
    name: str
    quantity: str
    units: str
    long_name: str
    dims: tuple
    coords: dict
    values: numpy.ndarray
    description: dict = field(default_factory=dict)

    def to_xarray(self):
        """The table as an xarray.DataArray with its axes as coordinates (needs xarray)."""
        import xarray
        attrs = {"units": self.units, "long_name": self.long_name, "quantity": self.quantity, "path": self.path}
        coords = {}
        for axis in self.description.get("axes", []):
            coords[axis["name"]] = (axis["name"], self.coords[axis["name"]], {"units": axis.get("units", ""), "long_name": axis.get("long_name", "")})
        if not coords:
            coords = {d: self.coords[d] for d in self.dims}
        return xarray.DataArray(self.values, dims=self.dims, coords=coords, name=self.path, attrs=attrs)


def fiber_from_melanin(eumelanin, pheomelanin, beta_m, beta_n):
    """A Fiber for the runtime: RGB sigma_a from d'Eon 2011's melanin model, roughness beta_m, beta_n [rad]."""
    return _core.fiber_from_melanin(_scalar(eumelanin, "eumelanin"), _scalar(pheomelanin, "pheomelanin"), _scalar(beta_m, "beta_m"),
                                    _scalar(beta_n, "beta_n"))


def _directions(w, name):
    a = numpy.ascontiguousarray(_real(w, name))
    if a.shape[-1:] != (3,):
        raise DomainError(f"{name} must end in an axis of 3 (a unit vector in the fiber frame), got shape {a.shape}")
    return a.shape[:-1], a.reshape(-1, 3)


class Scattering:
    """The C++ renderer runtime (hairlut::sampler::HairScattering<float>) over baked tables.

    Directions are unit vectors in the fiber frame (x along the fiber, root to tip), arrays of
    shape (..., 3) that broadcast against each other; the fiber is a Fiber (fiber_from_melanin, or
    Fiber(sigma_a=[r, g, b], beta_m=..., beta_n=...)). A NaN direction gives NaN (eval) or 0 (pdf).
    """

    def __init__(self, core, group):
        self._core = core
        self.group = group

    def _pair(self, a, b, na, nb):
        sa, _ = _directions(a, na)
        sb, _ = _directions(b, nb)
        shape = numpy.broadcast_shapes(sa, sb)
        full = [numpy.ascontiguousarray(numpy.broadcast_to(_real(w, n), shape + (3,))).reshape(-1, 3) for w, n in ((a, na), (b, nb))]
        return shape, full[0], full[1]

    def eval(self, fiber, wo, wi):
        """S(wo, wi) per RGB channel [1/sr], shape (..., 3)."""
        shape, a, b = self._pair(wo, wi, "wo", "wi")
        return self._core.eval(fiber, a, b).reshape(shape + (3,))

    def pdf(self, fiber, wo, wi):
        """The density per unit solid angle with which sample() draws wi at wo."""
        shape, a, b = self._pair(wo, wi, "wo", "wi")
        return self._core.pdf(fiber, a, b).reshape(shape)

    def albedo(self, fiber, wo):
        """The integral of S over directions at wo, averaged over the channels."""
        shape, a = _directions(wo, "wo")
        return self._core.albedo(fiber, a).reshape(shape)

    def sample(self, fiber, wo, u):
        """A direction drawn in proportion to S at wo from three uniform numbers u in [0, 1): a dict of
        wi (..., 3), weight = S / pdf per channel (..., 3), pdf (...) and the lobe drawn (...)."""
        shape, a, b = self._pair(wo, u, "wo", "u")
        r = self._core.sample(fiber, a, b)
        return {"wi": r["wi"].reshape(shape + (3,)), "weight": r["weight"].reshape(shape + (3,)), "pdf": r["pdf"].reshape(shape),
                "lobe": r["lobe"].reshape(shape)}

    def prepared(self, roughness):
        """This runtime (generic or Fourier tables) prepared for one roughness: roughness.beta_m,
        beta_n and tilt are read (its sigma_a is not). The result answers the same calls at about a
        material's cost, with every fiber's beta and tilt taken as these and its sigma_a its own
        (docs/library.md, "What a renderer calls")."""
        return Scattering(self._core.prepared(roughness), self.group)


class TableSet(dict):
    """Tables by path ("np/TRT", "mp/R", ...), with the set's provenance in .metadata.

    scattering() and sample() read the tables as a renderer does, through the C++ library: from
    the file the set was loaded from (or, for a bake, written to).
    """

    def __init__(self, raw, source=None):
        super().__init__()
        self.source = source
        self._loaded = None
        self.metadata = json.loads(raw["metadata"])
        self.files = list(raw.get("files", []))
        self.config_hash = raw.get("config_hash", self.metadata.get("config_hash"))
        for t in raw["tables"]:
            dims = tuple(t["dims"])
            self[t["path"]] = Table(path=t["path"], group=t["group"], name=t["name"], quantity=t["quantity"], units=t["units"],
                                    long_name=t["long_name"], dims=dims, coords=dict(zip(dims, t["coords"])), values=t["values"],
                                    description=json.loads(t["description"]))

    def to_xarray(self):
        """{path: xarray.DataArray} (tables of one set may use different nodes for an axis name)."""
        return {path: t.to_xarray() for path, t in self.items()}

    def _tables(self):
        if self._loaded is None:
            files = [f for f in ([self.source] if self.source else self.files) if str(f).endswith((".h5", ".exr"))]
            if not files:
                raise DomainError("this table set was baked in memory: bake(..., write=True) or load_tables(file) reads it as a renderer does")
            self._loaded = _core.Tables(os.fspath(files[0]))
        return self._loaded

    def scattering(self, group=""):
        """The renderer runtime (eval, sample, pdf, albedo) over the generic tables (group ""), or over
        one material of a per-material bake ("materials/<name>", or just "<name>")."""
        if group and "/" not in group:
            group = "materials/" + group
        return Scattering(self._tables().scattering(group), group)

    def domain(self, path):
        """The axes over which sample() reads table `path`, as the table's JSON axis descriptions
        (name, units, range, spacing, values, ...): the table's own, or, for a Fourier table
        (group np_fourier), the domain of N_p it stands for (beta, sigma_a, theta_d, phi; the
        residual's sigma_a, theta_d)."""
        return [json.loads(a) for a in self._tables().domain(path)]

    def domain_dims(self, path):
        """The axis names sample() takes for table `path` (domain())."""
        if self[path].group != "np_fourier":
            return self[path].dims
        return tuple(a["name"] for a in self.domain(path))

    def sample(self, path, **coords):
        """The quantity of table `path` at points, interpolated as the file declares (each axis's
        mapping and interpolation, and the factor table of N_p stored as a shape), as a renderer
        reads it; a Fourier table (np_fourier/<lobe>) gives N_p from its series. coords: one array
        per axis name (domain_dims(path)), broadcast; radians. NaN gives NaN."""
        dims = self.domain_dims(path)
        missing = [d for d in dims if d not in coords]
        extra = [k for k in coords if k not in dims]
        if missing or extra:
            raise DomainError(f"{path} has axes {', '.join(dims)}" + (f"; missing {', '.join(missing)}" if missing else "") +
                              (f"; unknown {', '.join(extra)}" if extra else ""))
        shape, flat = _broadcast(**{d: coords[d] for d in dims})
        points = numpy.ascontiguousarray(numpy.stack(flat, axis=1)) if flat[0].size else numpy.zeros((0, len(dims)))
        return self._tables().sample(path, points).reshape(shape)


def load_tables(file):
    """Loads an HDF5 or OpenEXR table file written by hairlut (the format is found from its bytes)."""
    return TableSet(_core.load_tables(os.fspath(file)), source=os.fspath(file))


def bake(config, threads=0, write=False, output_dir=None):
    """Bakes the tables of a config: a dict (the JSON document), or the path of a config file.

    Returns a TableSet. With write=True the files are written as bake-hair-luts writes them (to
    output_dir, or the config's output.directory; TableSet.files lists them).
    """
    if isinstance(config, dict):
        text, source, base = json.dumps(config), "<dict>", os.getcwd()
    else:
        text, source, base = "", os.fspath(config), ""
    return TableSet(_core.bake(text, source, base, _integer(threads, "threads"), bool(write), os.fspath(output_dir) if output_dir else ""))
