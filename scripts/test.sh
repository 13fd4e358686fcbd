#!/usr/bin/env bash
# Installs what is missing, builds everything and runs the whole test suite.
# GPU tests (ctest label "gpu") report a skip with the reason on machines
# without a CUDA device; run them on one with `ctest -L gpu`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
# astropy and pytest (PyPI) for the FITS test validation.fits_astropy and the
# Python module's tests (python.module), in a virtual environment inside the
# build folder, installed once and reused.
py=build/pyenv/bin/python
if ! "$py" -c "import astropy, numpy, pytest" 2>/dev/null; then
  # Debian's numpy and pytest stay visible, so the module's tests run even
  # where PyPI cannot be reached.
  /usr/bin/python3 -m venv --system-site-packages build/pyenv
  "$py" -m pip install --quiet --disable-pip-version-check astropy pytest ||
    echo "test.sh: warning: astropy could not be installed from PyPI; validation.fits_astropy will report a skip (python.module uses Debian's pytest)" >&2
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DNEBULA_PYTHON="$PWD/$py"
cmake --build build -j"$(nproc)"
cd build
ctest --output-on-failure -j"$(nproc)"
