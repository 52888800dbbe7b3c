#!/usr/bin/env bash
# Installs hairlut's build and test dependencies from Debian packages (Debian 12 "bookworm" or
# newer). Idempotent: packages already installed are left alone, and nothing is downloaded when
# everything is present. Uses sudo when not run as root.
#
# Optional test dependencies (the tests that need them are skipped, saying why, when missing) are
# installed with --with-optional (or HAIRLUT_SETUP_OPTIONAL=1).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libopenexr-dev libimath-dev openexr      # OpenEXR 3 (+ exrheader)
  libhdf5-dev hdf5-tools                   # HDF5 (+ h5dump)
  zlib1g-dev                               # deflate of HDF5 chunks on the baker's threads
  libcli11-dev                             # command lines
  catch2                                   # tests
  libboost-dev libboost-math-dev           # Bessel functions, quadrature, multiprecision
  nlohmann-json3-dev                       # configs and metadata
  libxxhash-dev                            # XXH3-64, the table files' checksums (header only)
  libpng-dev                               # render-hair-luts pictures
  libomp-dev                               # OpenMP runtime headers (GCC uses libgomp)
  python3 python3-numpy python3-h5py python3-jsonschema   # independent checks in tests
  python3-xarray python3-h5netcdf          # a netCDF-style client of the HDF5 tables
  python3-dev pybind11-dev                 # the Python module (hairlut package)
  python3-venv python3-pip                 # `pip install ./python` as the README shows it (docs test)
  json-schema-test-suite                   # the official JSON Schema tests (draft 7 files)
  clang libclang-rt-dev                    # libFuzzer with AddressSanitizer and UBSan (fuzz tests)
  libvulkan-dev glslang-tools spirv-tools  # the GLSL runtime's test: Vulkan loader and headers, SPIR-V built at build time
  mesa-vulkan-drivers                      # lavapipe: Vulkan on the CPU, so that the GLSL test runs without a GPU
)

optional=(
  chromium                                 # report.html rendered headless: layout test, screenshots
)
if [ "${1:-}" = "--with-optional" ] || [ "${HAIRLUT_SETUP_OPTIONAL:-0}" = "1" ]; then
  packages+=("${optional[@]}")
else
  for p in "${optional[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' ||
      echo "setup-debian: optional test dependency $p is not installed (--with-optional installs it)"
  done
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-debian: all ${#packages[@]} packages present"
  exit 0
fi

echo "setup-debian: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup-debian: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
