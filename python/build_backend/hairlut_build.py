"""A PEP 517 build backend for the hairlut Python package, with the standard library only.

pip runs it for `pip install ./python`: it configures the repository around python/ with CMake
(for the Python that runs pip), builds the extension target hairlut_python and packs
hairlut/__init__.py and hairlut/_core*.so into a wheel. No build requirement is downloaded.

Environment: HAIRLUT_BUILD_DIR, a build tree to configure or reuse (default:
<repository>/build/pip-<python tag>); HAIRLUT_BUILD_JOBS, parallel compile jobs (default 2).
"""

import base64
import hashlib
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

_PYTHON_DIR = Path(__file__).resolve().parent.parent
_SOURCE = _PYTHON_DIR.parent


def _version():
    text = (_SOURCE / "CMakeLists.txt").read_text()
    m = re.search(r"project\(\s*hairlut\s+VERSION\s+([0-9.]+)", text)
    if not m:
        raise RuntimeError(f"{_SOURCE / 'CMakeLists.txt'}: no project(hairlut VERSION x.y.z)")
    return m.group(1)


def _tag():
    impl = f"cp{sys.version_info[0]}{sys.version_info[1]}"
    abi = impl + getattr(sys, "abiflags", "")
    plat = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{impl}-{abi}-{plat}"


def _run(args, **kw):
    print("hairlut build:", " ".join(str(a) for a in args), flush=True)
    subprocess.run([str(a) for a in args], check=True, **kw)


def _build_extension():
    """Configures (when needed) and builds hairlut_python; returns the folder holding hairlut/."""
    tag = f"cp{sys.version_info[0]}{sys.version_info[1]}"
    build = Path(os.environ.get("HAIRLUT_BUILD_DIR") or _SOURCE / "build" / f"pip-{tag}").resolve()
    cmake = shutil.which("cmake")
    if not cmake:
        raise RuntimeError("cmake not found (Debian: apt-get install cmake; scripts/setup-debian.sh installs every dependency)")
    if not (build / "CMakeCache.txt").exists():
        args = [cmake, "-S", _SOURCE, "-B", build, "-DCMAKE_BUILD_TYPE=Release", f"-DHAIRLUT_PYTHON={sys.executable}",
                "-DHAIRLUT_BUILD_TESTS=OFF", "-DHAIRLUT_BUILD_TOOLS=OFF", "-DHAIRLUT_INSTALL=OFF"]
        if shutil.which("ccache"):
            args += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache", "-DCMAKE_C_COMPILER_LAUNCHER=ccache"]
        _run(args)
    _run([cmake, "--build", build, "--target", "hairlut_python", "--parallel", os.environ.get("HAIRLUT_BUILD_JOBS", "2")])
    package = build / "python" / "hairlut"
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    if not (package / f"_core{suffix}").exists():
        found = ", ".join(p.name for p in package.glob("_core*")) or "nothing"
        raise RuntimeError(f"{package}: no _core{suffix} for {sys.executable} (found {found}); the build tree "
                           f"{build} was configured for another Python (HAIRLUT_PYTHON) or without pybind11 (Debian: pybind11-dev)")
    return package, suffix


def _record_line(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def _metadata(version):
    return (f"Metadata-Version: 2.1\nName: hairlut\nVersion: {version}\n"
            "Summary: Hair-fiber scattering lookup tables: d'Eon 2011 M_p and N_p, baking, baked tables and the renderer runtime\n"
            "License: Apache-2.0\nRequires-Python: >=3.9\nRequires-Dist: numpy\n")


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    version = _version()
    info = Path(metadata_directory) / f"hairlut-{version}.dist-info"
    info.mkdir(parents=True, exist_ok=True)
    (info / "METADATA").write_text(_metadata(version))
    return info.name


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    version = _version()
    package, suffix = _build_extension()
    files = {"hairlut/__init__.py": (_PYTHON_DIR / "hairlut" / "__init__.py").read_bytes(),
             f"hairlut/_core{suffix}": (package / f"_core{suffix}").read_bytes()}
    info = f"hairlut-{version}.dist-info"
    files[f"{info}/METADATA"] = _metadata(version).encode()
    files[f"{info}/WHEEL"] = f"Wheel-Version: 1.0\nGenerator: hairlut_build\nRoot-Is-Purelib: false\nTag: {_tag()}\n".encode()
    files[f"{info}/top_level.txt"] = b"hairlut\n"
    record = [_record_line(name, data) for name, data in files.items()] + [f"{info}/RECORD,,"]
    files[f"{info}/RECORD"] = ("\n".join(record) + "\n").encode()
    name = f"hairlut-{version}-{_tag()}.whl"
    Path(wheel_directory).mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(Path(wheel_directory) / name, "w", compression=zipfile.ZIP_DEFLATED) as z:
        for path, data in files.items():
            info_ = zipfile.ZipInfo(path, date_time=(1980, 1, 1, 0, 0, 0))
            info_.external_attr = (0o755 if path.endswith(suffix) else 0o644) << 16
            info_.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info_, data)
    return name
