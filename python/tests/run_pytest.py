"""ctest entry of one pytest file: exits 77 (ctest: skipped) when pytest, NumPy or SciPy is not installed
for this interpreter, else runs pytest on the file and returns its exit code."""
import importlib.util
import sys

missing = [m for m in ("pytest", "numpy", "scipy") if importlib.util.find_spec(m) is None]
if missing:
    print("skipped: %s not installed for %s (Debian: python3-pytest python3-numpy python3-scipy)" % (", ".join(missing), sys.executable))
    sys.exit(77)
import pytest  # noqa: E402

sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", *sys.argv[1:]]))
