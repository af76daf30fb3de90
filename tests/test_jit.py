"""jit.py: the compiled kernels survive an install where numba cannot write its cache."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import clearjoint

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


def test_a_change_to_the_law_reaches_the_cached_kernels_that_inline_it(tmp_path: Path) -> None:
    # numba's cache tracks a kernel's own file only; the kernel inlines laws/clearance.py
    package = tmp_path / "clearjoint"
    shutil.copytree(
        Path(clearjoint.__file__).parent, package, ignore=shutil.ignore_patterns("__pycache__")
    )
    env = {**os.environ, "PYTHONPATH": str(tmp_path)}
    env.pop("NUMBA_CACHE_DIR", None)

    def region_force() -> str:
        done = subprocess.run(
            [sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, check=False
        )
        assert done.returncode == 0, done.stderr
        return done.stdout.strip()

    assert region_force() == "(1010.0, 500.0)"
    assert list(package.rglob("*.nbi"))  # compiled and cached
    law = package / "laws" / "clearance.py"
    text = law.read_text(encoding="utf-8")
    assert text.count("return k0 + k_c, k_c * g_c") == 1
    law.write_text(text.replace("return k0 + k_c, k_c * g_c", "return k0 + k_c, 2.0 * k_c * g_c"))
    assert region_force() == "(1010.0, 1000.0)"  # the kernel was compiled anew
    assert region_force() == "(1010.0, 1000.0)"  # and cached again
