"""A first run says why it is slow (issue 28, Build 2): "compiling the solvers, first run
only" when numba compiles, on ``simulate`` too (its steady state is a compiled kernel's);
``--quiet`` keeps stderr for warnings and errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numba import njit

from clearjoint import cli, cli_progress, studies
from clearjoint.errors import ParameterError

STUDY = str(Path(__file__).resolve().parents[1] / "examples" / "study.toml")


def _compiles_then_stops(*_args: object) -> None:
    """A stand-in for the run whose kernels are not cached yet: numba compiles one."""

    @njit  # a new function: compiled here, whatever the cache holds
    def twice(x: np.ndarray) -> np.ndarray:
        return 2.0 * x

    twice(np.ones(2))
    raise ParameterError("stopped after the compile")


@pytest.mark.parametrize("quiet", [False, True])
def test_simulate_says_it_compiles_on_a_first_run(
    quiet: bool, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(cli_progress, "PROGRESS_LINES_IN_PROCESS", True)  # as the command
    monkeypatch.setattr(studies, "run_study", _compiles_then_stops)
    code = cli.main(["simulate", STUDY, *(["--quiet"] if quiet else [])])
    assert code == 2
    said = [] if quiet else ["clearjoint simulate: compiling the solvers, first run only"]
    assert capsys.readouterr().err.splitlines() == [
        *said,
        "clearjoint simulate: error: stopped after the compile",
    ]
