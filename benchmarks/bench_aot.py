"""Ahead-of-time compiled kernels (numba.pycc) for the frf command: the compile's time, and
whether the results are the JIT's to the bit. A probe for issue 28's cold run, on demand.

``python benchmarks/bench_aot.py``: (1) runs ``clearjoint frf examples/frf.toml --from 10Hz
--to 360Hz`` in a subprocess and reads the signatures numba compiled for the four kernels
the curve calls from Python (``periodic``'s ``arclength_step``, ``correct_orbit``,
``start_state``; ``exact.kernel.advance``); (2) compiles them, with every kernel they call,
into one extension module by ``numba.pycc`` in a fresh process with an empty numba cache,
and times it; (3) runs the command twice more in this order, with the JIT kernels and with
``clearjoint.periodic``'s three names bound to the extension's, and compares the two
netCDF files variable by variable, bit for bit. The other kernels of the command stay
JIT-compiled (loaded from numba's cache) in both runs. Nothing here is used by clearjoint.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
COMMAND = ["frf", str(ROOT / "examples/frf.toml"), "--from", "10Hz", "--to", "360Hz"]
EXPORTS = [
    ("arclength_step", "clearjoint.exact.shooting"),
    ("correct_orbit", "clearjoint.exact.shooting"),
    ("start_state", "clearjoint.exact.shooting"),
    ("advance", "clearjoint.exact.kernel"),
]

SIGNATURES = """
import importlib, pickle, runpy, sys
sys.argv = ["clearjoint", *{command!r}, "--out", {out!r}, "--force", "--quiet"]
try:
    runpy.run_module("clearjoint", run_name="__main__")
except SystemExit:
    pass
found = {{}}
for name, module in {exports!r}:
    dispatcher = getattr(importlib.import_module(module), name)
    found[name] = dispatcher.overloads[dispatcher.signatures[0]].signature
pickle.dump(found, open({pickle!r}, "wb"))
"""

BUILD = """
import importlib, pickle, time
from numba.pycc import CC
found = pickle.load(open({pickle!r}, "rb"))
cc = CC("clearjoint_aot_probe")
cc.output_dir = {folder!r}
for name, module in {exports!r}:
    cc.export(name, found[name])(getattr(importlib.import_module(module), name).py_func)
start = time.perf_counter()
cc.compile()
print(f"{{time.perf_counter() - start:.1f}}")
"""

RUN = """
import runpy, sys, time
sys.path.insert(0, {folder!r})
if {aot!r}:
    import clearjoint.periodic as periodic
    import clearjoint_aot_probe as aot
    periodic.arclength_step = aot.arclength_step
    periodic.correct_orbit = aot.correct_orbit
    periodic.start_state = aot.start_state
sys.argv = ["clearjoint", *{command!r}, "--out", {out!r}, "--force", "--quiet"]
start = time.perf_counter()
try:
    runpy.run_module("clearjoint", run_name="__main__")
except SystemExit:
    pass
print(f"{{time.perf_counter() - start:.2f}}")
"""


def _python(code: str, env: dict[str, str] | None = None) -> str:
    done = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        cwd=ROOT,
        env=env,
        check=True,
        capture_output=True,
        text=True,
    )
    return done.stdout.strip().splitlines()[-1] if done.stdout.strip() else ""


def main() -> None:
    import xarray as xr

    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        pickle = str(folder / "signatures.pkl")
        _python(
            SIGNATURES.format(
                command=COMMAND, out=str(folder / "first.nc"), exports=EXPORTS, pickle=pickle
            )
        )
        empty = dict(os.environ, NUMBA_CACHE_DIR=str(folder / "empty-cache"))
        t0 = time.perf_counter()
        seconds = _python(
            BUILD.format(pickle=pickle, folder=str(folder), exports=EXPORTS), env=empty
        )
        wall = time.perf_counter() - t0
        print(
            f"numba.pycc, 4 exported kernels with all they call, fresh process, empty cache: "
            f"compile {seconds} s ({wall:.1f} s with the imports)"
        )
        runs = {}
        for aot in (False, True):
            out = str(folder / f"{'aot' if aot else 'jit'}.nc")
            runs[aot] = _python(RUN.format(folder=str(folder), aot=aot, command=COMMAND, out=out))
        print(f"frf warm: JIT kernels {runs[False]} s, the extension's {runs[True]} s")
        jit = xr.open_dataset(folder / "jit.nc")
        aot = xr.open_dataset(folder / "aot.nc")
        numeric = [v for v in jit.data_vars if jit[v].dtype.kind in "fiu"]
        same = jit.identical(aot) and all(
            jit[v].values.tobytes() == aot[v].values.tobytes() for v in numeric
        )
        print(
            f"the two netCDF files: {'equal to the bit' if same else 'DIFFERENT'} "
            f"({len(numeric)} numeric variables by their bytes, all by xarray.identical)"
        )
        jit.close()
        aot.close()


if __name__ == "__main__":
    main()
