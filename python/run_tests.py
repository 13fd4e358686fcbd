"""Runs the Python module's tests with pytest; exit 77 (ctest's skip) when
pytest or numpy is missing (scripts/test.sh installs them)."""
import sys

try:
    import numpy  # noqa: F401
    import pytest
except ImportError as e:
    print(f"python.module: skipped: {e} (scripts/test.sh installs pytest in build/pyenv)")
    sys.exit(77)

source, work = sys.argv[1], sys.argv[2]
sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", "--basetemp", work, f"{source}/test_nebula.py"]))
