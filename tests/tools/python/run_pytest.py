"""Runs one test file of the magsim module under pytest; exit 77 (CTest's skip) when pytest or
numpy is not installed, so that a machine without them skips instead of failing."""
import sys

try:
    import numpy  # noqa: F401
    import pytest
except ImportError as e:
    print(f"skipped: {e} (install python3-pytest and python3-numpy)")
    sys.exit(77)

sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", *sys.argv[1:]]))
