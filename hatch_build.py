"""Build hook: compile the solvers' kernels ahead of time into the wheel (clearjoint.compiled).

hatchling runs it when it builds a wheel, standard or editable. It compiles the kernels in
a subprocess, from this source tree (``python -m clearjoint.compiled``), into
``src/clearjoint/_kernels_<digest>.<suffix>`` (kept there, ignored by git: an up-to-date
module is not compiled again); a standard wheel also carries that file, an editable
install imports it from the source tree. Where the compile cannot run (no C compiler,
say) the wheel is built without it, with a warning, and the kernels compile at first use
as before. ``CLEARJOINT_COMPILED=0`` in the environment skips the compile.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

from hatchling.builders.hooks.plugin.interface import BuildHookInterface

_EXCEPTION = re.compile(r"^[A-Za-z_][\w.]*(Error|Exception|Exit)\b.*")


def failure_reason(stderr: str) -> str:
    """The line of a failed compile's output that says why: its last exception's line.

    numba's message for a missing C compiler ends on a conda hint (``#> conda install
    gcc_linux-64 gxx_linux-64``), which alone does not say what failed.
    """
    lines = [line.strip() for line in stderr.strip().splitlines() if line.strip()]
    said = [line for line in lines if _EXCEPTION.match(line)]
    return (said or lines or ["no output"])[-1]


class CompiledKernels(BuildHookInterface):  # type: ignore[misc]
    """Compile :data:`clearjoint.compiled.EXPORTS` and put the module into the wheel."""

    PLUGIN_NAME = "custom"

    def initialize(self, version: str, build_data: dict[str, Any]) -> None:
        if self.target_name != "wheel" or os.environ.get("CLEARJOINT_COMPILED", "1") == "0":
            return
        root = Path(self.root)
        # this source first, then whatever the build environment has on the path (pip's
        # isolated build puts its own site folder there)
        path = [str(root / "src"), *filter(None, [os.environ.get("PYTHONPATH")])]
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(path))
        self.app.display_info(
            "clearjoint: compiling the solvers' kernels (about 30 s of CPU; "
            "nothing when an up-to-date module is there)"
        )
        try:
            done = subprocess.run(
                [sys.executable, "-m", "clearjoint.compiled"],
                cwd=root,
                env=env,
                capture_output=True,
                text=True,
                check=False,
                timeout=3600,
            )
        except (OSError, subprocess.SubprocessError) as exc:
            self._skip(str(exc))
            return
        lines = done.stdout.strip().splitlines()
        if done.returncode != 0 or not lines or not Path(lines[-1]).is_file():
            self._skip(failure_reason(done.stderr))
            return
        module = Path(lines[-1])
        if version == "editable":
            return  # an editable install imports the package, and the module, from src/
        build_data["force_include"][str(module)] = f"clearjoint/{module.name}"
        build_data["pure_python"] = False
        build_data["infer_tag"] = True

    def _skip(self, reason: str) -> None:
        self.app.display_warning(
            f"clearjoint: the kernels were not compiled ahead of time ({reason}); "
            "they will compile at their first use instead"
        )
