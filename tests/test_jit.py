"""jit.py: the compiled kernels survive an install where numba cannot write its cache."""

from __future__ import annotations

import os
import subprocess
import sys

SCRIPT = """
import warnings
warnings.simplefilter("always")
import numpy as np
from clearjoint.exact import kernel as kn
p = np.zeros(kn.N_PARAMS)
p[kn.P_K0], p[kn.P_KC], p[kn.P_GC] = 10.0, 1000.0, 0.5
print(kn.region_force(p, kn.COMPRESSION))
"""


def test_no_writable_cache_folder_compiles_without_one_and_says_so() -> None:
    # numba's own failure mode of a read-only install with no writable cache folder:
    # no cache locator accepts the source file (here, only the notebook locator is allowed)
    env = {**os.environ, "NUMBA_CACHE_LOCATOR_CLASSES": "IPythonCacheLocator"}
    env.pop("NUMBA_CACHE_DIR", None)
    result = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, check=False
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "(1010.0, 500.0)"  # K = k0 + k_c, Fc = k_c g_c
    assert "set NUMBA_CACHE_DIR to a writable folder" in result.stderr
    assert result.stderr.count("CacheWarning") == 1
