"""The reproduction of the paper's study, written as a self-contained report.

Today the study covers MODEL.md section 1 (the stiffness coefficient of eq 9
and its exact generalisation, the paper's Fig. 12) and one exact steady cycle
of the forced joint with its energy ledger (Fig. 7); the later stages
(dissipation model, virtual rig, identification, fitted laws) are listed in the
report as not built yet.
"""

from __future__ import annotations

import base64
import html
import io
import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from clearjoint import stiffness
from clearjoint._checks import refuse_to_overwrite
from clearjoint.figures import Curve, displacement_stages_figure, stiffness_coefficient_figure
from clearjoint.joint import Friction, Joint
from clearjoint.simulate import SteadyState, steady_state

#: The paper's two joints (c = 0.106 mm and 0.196 mm).
PAPER_CLEARANCES: tuple[float, ...] = (0.106e-3, 0.196e-3)

#: Stages of the paper's study that this version does not run yet.
NOT_BUILT: tuple[str, ...] = (
    "fitted laws (eq 19-22) and the joint stiffness of eq 20",
)


@dataclass(frozen=True)
class StiffnessStudy:
    """c_d against A for the paper's clearances (eq 9) and an exact k0 > 0, k_t < k_c joint.

    Attributes
    ----------
    amplitudes : (N,) ndarray
        Penetration A, m.
    curves : tuple of Curve
        c_d(A) per joint, labelled.
    joints : tuple of Joint
        The joint behind each curve.
    """

    amplitudes: np.ndarray
    curves: tuple[Curve, ...]
    joints: tuple[Joint, ...]


def stiffness_study(
    clearances: Sequence[float] = PAPER_CLEARANCES,
    *,
    contact_stiffness: float = 8.0e7,
    mass: float = 2.0,
    gap_stiffness_ratio: float = 0.05,
    tension_ratio: float = 0.7,
    max_amplitude: float = 0.5e-3,
    points: int = 400,
) -> StiffnessStudy:
    """Return c_d(A) for each clearance: eq 9 (k0 = 0) and the exact curve for k0 > 0, k_t < k_c.

    c_d depends only on A/c, k0/k_c and k_t/k_c, so the mass and the contact
    stiffness set the scale of k_d but not the curves.
    """
    amplitudes = np.linspace(0.0, max_amplitude, points)
    curves: list[Curve] = []
    joints: list[Joint] = []
    for clearance in clearances:
        paper = Joint(mass=mass, clearance=clearance, compression_stiffness=contact_stiffness)
        joints.append(paper)
        label = f"c = {clearance * 1e3:.3f} mm, eq 9 (k0 = 0)"
        curves.append(Curve(amplitudes, stiffness.stiffness_coefficient(paper, amplitudes), label))
    for clearance in clearances:
        general = Joint(
            mass=mass,
            clearance=clearance,
            compression_stiffness=contact_stiffness,
            tension_stiffness=tension_ratio * contact_stiffness,
            gap_stiffness=gap_stiffness_ratio * contact_stiffness,
        )
        joints.append(general)
        label = (
            f"c = {clearance * 1e3:.3f} mm, exact, k0 = {gap_stiffness_ratio:g} k_c, "
            f"k_t = {tension_ratio:g} k_c"
        )
        curves.append(
            Curve(amplitudes, stiffness.stiffness_coefficient(general, amplitudes), label)
        )
    return StiffnessStudy(amplitudes, tuple(curves), tuple(joints))


def example_cycle() -> SteadyState:
    """The exact steady cycle of the c = 0.106 mm joint at 1 kN, 400 Hz (examples/study.toml)."""
    joint = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7, tension_stiffness=5e7)
    return steady_state(
        joint,
        1000.0,
        2.0 * np.pi * 400.0,
        damping_ratio=0.01,
        restitution=0.8,
        friction=Friction(0.2, 300.0),
        samples_per_period=512,
    )


def _png(fig: Figure) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=120)
    return buffer.getvalue()


def _html_report(figures: dict[str, bytes], study: StiffnessStudy) -> str:
    rows = "".join(
        f"<tr><td>{html.escape(curve.label)}</td>"
        f"<td>{joint.clearance * 1e3:.3f}</td>"
        f"<td>{joint.gap_stiffness:.3g}</td>"
        f"<td>{joint.compression_stiffness:.3g}</td>"
        f"<td>{joint.tension_stiffness:.3g}</td></tr>"
        for curve, joint in zip(study.curves, study.joints, strict=True)
    )
    images = "".join(
        f'<figure><img alt="{html.escape(name)}" src="data:image/png;base64,'
        f'{base64.b64encode(data).decode("ascii")}"><figcaption>{html.escape(name)}'
        "</figcaption></figure>"
        for name, data in figures.items()
    )
    missing = "".join(f"<li>{html.escape(item)}</li>" for item in NOT_BUILT)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>clearjoint reproduction</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:2em auto}}
table{{border-collapse:collapse}}td,th{{border:1px solid #999;padding:0.2em 0.5em}}</style>
</head><body>
<h1>clearjoint: reproduction of the clearance-joint study</h1>
<p>Li et al., Shock and Vibration (2013), doi:10.1155/2013/583030; equations as rebuilt in
MODEL.md.</p>
<h2>Dynamic stiffness coefficient (paper Fig. 12, MODEL.md eq 9)</h2>
<p>c<sub>d</sub> = k<sub>d</sub>/k<sub>&infin;</sub> from the exact period of free vibration.
For k0 = 0 and a symmetric joint it is (&pi;A/(&pi;A + c))<sup>2</sup>.</p>
{images}
<table><tr><th>curve</th><th>c (mm)</th><th>k0 (N/m)</th><th>k<sub>c</sub> (N/m)</th>
<th>k<sub>t</sub> (N/m)</th></tr>{rows}</table>
<h2>Not built yet</h2><ul>{missing}</ul>
</body></html>
"""


def reproduce(
    out_dir: Path,
    *,
    force: bool = False,
    progress: Callable[[str], None] | None = None,
) -> list[Path]:
    """Run the study and write ``report.html``, ``results.json`` and the figures into ``out_dir``.

    Raises
    ------
    OutputExistsError
        One of the files exists and ``force`` is False.
    """
    say = progress or (lambda _message: None)
    out_dir = Path(out_dir)
    targets = {
        "report": out_dir / "report.html",
        "results": out_dir / "results.json",
        "fig12": out_dir / "fig12_stiffness_coefficient.png",
        "fig7": out_dir / "fig7_displacement_stages.png",
    }
    refuse_to_overwrite(targets.values(), force=force)
    say("stiffness study (MODEL.md section 1, Fig. 12)")
    study = stiffness_study()
    png = _png(stiffness_coefficient_figure(study.curves))
    say("exact steady cycle of the forced joint (MODEL.md section 2, Fig. 7)")
    cycle = example_cycle()
    stages = [(st.name, st.start, st.end) for st in cycle.stages]
    png7 = _png(displacement_stages_figure(cycle.time, cycle.displacement, stages))
    out_dir.mkdir(parents=True, exist_ok=True)
    targets["fig12"].write_bytes(png)
    targets["fig7"].write_bytes(png7)
    results = {
        "stiffness_coefficient": {
            "amplitude_m": study.amplitudes.tolist(),
            "curves": [
                {
                    "label": curve.label,
                    "clearance_m": joint.clearance,
                    "gap_stiffness_n_per_m": joint.gap_stiffness,
                    "compression_stiffness_n_per_m": joint.compression_stiffness,
                    "tension_stiffness_n_per_m": joint.tension_stiffness,
                    "stiffness_coefficient": curve.y.tolist(),
                }
                for curve, joint in zip(study.curves, study.joints, strict=True)
            ],
        },
        "example_cycle": {
            "amplitude_m": cycle.amplitude,
            "period_multiple": cycle.period_multiple,
            "energy_j": cycle.energy.as_dict(),
            "balance_error": cycle.energy.balance_error,
        },
        "not_built_yet": list(NOT_BUILT),
    }
    targets["results"].write_text(json.dumps(results, indent=1), encoding="utf-8")
    targets["report"].write_text(
        _html_report(
            {
                "Fig. 12: stiffness coefficient against amplitude": png,
                "Fig. 7: exact steady cycle of the c = 0.106 mm joint, 1 kN at 400 Hz, "
                f"energy balance error {cycle.energy.balance_error:.1e}": png7,
            },
            study,
        ),
        encoding="utf-8",
    )
    return list(targets.values())
