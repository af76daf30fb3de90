"""Every public result class has the common interface: a short repr, plot, to_xarray, to_pandas."""

from __future__ import annotations

import importlib

import pytest

#: Every public result class and the module it is defined in (``grep -n "^class " -r src``).
RESULTS = [
    ("clearjoint.results.motion", "EnergyLedger"),
    ("clearjoint.results.motion", "Stage"),
    ("clearjoint.results.motion", "Motion"),
    ("clearjoint.results.motion", "SteadyState"),
    ("clearjoint.results.motion", "FrequencySweep"),
    ("clearjoint.results.orbit", "PeriodicOrbit"),
    ("clearjoint.results.response", "FrequencyResponse"),
    ("clearjoint.results.response", "ResponseEvent"),
    ("clearjoint.dissipation", "Energies"),
    ("clearjoint.dissipation", "Comparison"),
    ("clearjoint.dissipation", "AgreementMap"),
    ("clearjoint.stiffness", "FreeOrbit"),
    ("clearjoint.stiffness", "ResponseBranch"),
    ("clearjoint.stiffness", "StiffnessCurve"),
    ("clearjoint.harmonic.modes", "NonlinearMode"),
    ("clearjoint.structure.motion", "StructureMotion"),
    ("clearjoint.structure.backbone", "Backbone"),
    ("clearjoint.structure.model", "Modes"),
    ("clearjoint.identify.result", "Identification"),
    ("clearjoint.identify.result", "CycleResult"),
]


@pytest.mark.parametrize(("module", "name"), RESULTS, ids=[name for _, name in RESULTS])
def test_every_result_class_has_the_four(module: str, name: str) -> None:
    """Its own repr (not the dataclass one, which would print the arrays) and the three methods."""
    cls = getattr(importlib.import_module(module), name)
    own = cls.__repr__
    assert own is not object.__repr__
    assert own.__code__.co_filename.endswith(".py"), f"{name} has the generated dataclass repr"
    for method in ("plot", "to_xarray", "to_pandas"):
        assert callable(getattr(cls, method, None)), f"{name} has no {method}"


def test_the_results_package_imports_no_solver() -> None:
    """Importing clearjoint.results loads no solver (simulate, periodic, harmonic, ...)."""
    import subprocess
    import sys

    code = (
        "import sys, clearjoint.results; "
        "print(sorted(m for m in sys.modules if m.startswith('clearjoint')))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    for solver in ("simulate", "periodic", "harmonic", "structure", "continuation"):
        assert f"clearjoint.{solver}" not in loaded


@pytest.mark.parametrize(
    ("old", "name"),
    [
        ("clearjoint.periodic", "FrequencyResponse"),
        ("clearjoint.periodic", "ResponseEvent"),
        ("clearjoint.periodic", "PeriodicOrbit"),
        ("clearjoint.simulate", "Motion"),
        ("clearjoint.simulate", "SteadyState"),
        ("clearjoint.simulate", "FrequencySweep"),
        ("clearjoint.simulate", "EnergyLedger"),
        ("clearjoint.simulate", "Stage"),
        ("clearjoint.simulate.core", "Motion"),
        ("clearjoint.simulate.core", "SteadyState"),
        ("clearjoint.simulate.core", "Stage"),
        ("clearjoint.simulate.core", "EnergyLedger"),
        ("clearjoint.simulate.core", "FrequencySweep"),
    ],
)
def test_the_old_import_paths_give_the_same_classes(old: str, name: str) -> None:
    import clearjoint.results

    assert getattr(importlib.import_module(old), name) is getattr(clearjoint.results, name)
