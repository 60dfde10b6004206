"""Export a specimen as a standalone OpenSeesPy script (`opensees`).

The script builds the same model as the toolkit: in full contact and uplifted the
linear systems of `multimass.modal.linearisation` exactly (their eigenvalues agree
to round-off), while rocking a nonlinear model on compression-only contact springs
(`_rocking`). It runs by itself (``python model.py``) and exposes ``build(ops)`` to
add the model to the current OpenSees domain.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..inputs.records import Record
from ..model.structure import Structure, from_specimen
from . import _column, _rocking, _script
from ._runtime import loader_source

__all__ = ["opensees", "PHASES", "default_dt"]

#: Phases the exporter writes: name -> what the model is.
PHASES = {
    "full-contact": "linear, base fixed to the ground (paper 001, Eq 3)",
    "uplifted": "linear, rocking on the right pivot, linearised about θ = 0 (paper 001, Eqs 19-20)",
    "rocking": "nonlinear: a rigid base on two compression-only contact springs at the pivots",
}

# tags, added to OFFSET in the script: node i and beam i use i (1..N <= 200)
_TAGS = {
    "BASE": 1000,
    "PIVOT": 1001,
    "BASE_SPRING": 1000,
    "FRAME": 2000,
    "ANCHOR": 3000,
    "GRAVITY_NEG": 3000,
    "GRAVITY_POS": 4000,
    "DASHPOT": 5000,
    "GROUND_SERIES": 2,
    "GRAVITY_SERIES": 1,
}


def _structure(specimen) -> Structure:
    if isinstance(specimen, Structure):
        return specimen
    return from_specimen(specimen)


def _check_phase(phase, s: Structure) -> str:
    if not isinstance(phase, str) or phase.replace("_", "-") not in PHASES:
        raise InputError(f"`phase` = {phase!r}: use one of {', '.join(PHASES)}")
    phase = phase.replace("_", "-")
    if s.is_rigid and phase != "rocking":
        raise InputError(
            f"`phase` = {phase!r}: {s.name} is a rigid block, which has no elastic "
            "degree of freedom to vibrate in full contact and one unstable one uplifted; "
            "export it with phase 'rocking'"
        )
    return phase


def default_dt(s: Structure, phase: str, record: Record | None, output_dt: float = 1e-3) -> float:
    """The analysis step (s): the output step (or the record's, when it is not a whole
    multiple of the output step) divided by a whole number of steps.

    Linear phases: ω_2 dt ≤ 0.05 at the second full-contact mode (Newmark's period
    error (ω dt)²/12 ≤ 2e-4 there, ≤ 1e-5 at mode 1). Rocking: 20 steps per period of
    the contact springs (`_rocking.contact`).
    """
    if phase == "rocking":
        limit = 2.0 * math.pi / _rocking.contact(s)["omega_c"] / 20.0
    else:
        omega = s.full_contact_omega
        limit = 0.05 / omega[min(1, omega.size - 1)]
    base = output_dt
    if record is not None:
        ratio = record.dt / output_dt
        base = output_dt if abs(ratio - round(ratio)) < 1e-9 * ratio else record.dt
    return base / math.ceil(base / limit)


def _check_out(out) -> Path | None:
    """The script's path, checked writable (its missing folders are made when writing)."""
    if out is None:
        return None
    if not isinstance(out, (str, os.PathLike)) or isinstance(out, bytes) or str(out) == "":
        raise InputError(f"`out` = {out!r:.80}: give the path of the script to write")
    path = Path(out)
    if path.is_dir():
        raise InputError(f"`out` = {str(path)!r} is a folder; give a file name, e.g. model.py")
    folder = path.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise InputError(f"`out` = {str(path)!r}: {str(folder)!r} is a file, not a folder")
    if not os.access(folder, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise InputError(f"`out` = {str(path)!r}: not writable here; choose another path")
    return path


def _positive(name: str, value, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < math.inf:
        raise InputError(f"`{name}` = {value!r:.40}: give {what} (a finite number > 0)")
    return float(value)


def opensees(
    specimen,
    phase: str = "full-contact",
    record: Record | None = None,
    *,
    out=None,
    t_end: float | None = None,
    dt: float | None = None,
    output_dt: float = 1e-3,
    release: float | None = None,
    contact_damping: float | None = None,
    offset: int = 0,
) -> str:
    """The OpenSeesPy script of a specimen's model in one phase.

    Parameters
    ----------
    specimen : Structure, specimen, bundled name or TOML path
        A column (any phase) or a rigid block ("rocking" only).
    phase : {"full-contact", "uplifted", "rocking"}
        See `PHASES`.
    record : Record, optional
        Ground motion (`multimass.read_record`), written into the script.
    out : path, optional
        Where to write the script; checked before anything is computed.
    t_end : float, optional
        End of the analysis (s); default the record's last sample, or 5 s.
    dt : float, optional
        Analysis step (s); default `default_dt`.
    output_dt : float
        Recorders' sampling step (s).
    release : float, optional
        Rocking only: release from rest at θ0 = `release` rad (|θ0| < α_cg).
    contact_damping : float, optional
        Rocking only: damping ratio ζ_c of the contact springs; default by kind,
        0.01 for a block and 0.1 for a column (`_rocking.CONTACT_DAMPING`).
    offset : int
        Added to every tag, to place the model beside others in one domain.

    Returns
    -------
    str
        The script's text (also written to `out` if given).

    Raises
    ------
    InputError
        For a phase or kind that cannot be exported, an unwritable `out`, or any
        invalid value (named in the message), before anything is written.
    """
    path = _check_out(out)
    s = _structure(specimen)
    phase = _check_phase(phase, s)
    if record is not None and not isinstance(record, Record):
        raise InputError(
            f"`record` is a {type(record).__name__}: give a multimass.Record "
            "(multimass.read_record(path, units=..., scale=...))"
        )
    if release is not None:
        if phase != "rocking":
            raise InputError(f"`release` = {release!r}: a free release needs phase 'rocking'")
        release = float(release)
        if not math.isfinite(release) or release == 0.0 or abs(release) >= s.alpha_cg:
            raise InputError(
                f"`release` = {release!r} rad: give 0 < |θ0| < α_cg = {s.alpha_cg:.4g} rad "
                "(beyond it the structure overturns)"
            )
    if isinstance(offset, bool) or not isinstance(offset, int) or offset < 0:
        raise InputError(f"`offset` = {offset!r}: give a whole number >= 0 added to every tag")
    output_dt = _positive("output_dt", output_dt, "the recorders' step in s")
    if contact_damping is None:
        contact_damping = _rocking.contact(s)["zeta_c"]
    contact_damping = _positive("contact_damping", contact_damping, "a damping ratio")
    if t_end is None:
        t_end = float(record.duration) if record is not None else 5.0
    t_end = _positive("t_end", t_end, "the end time in s")
    dt = (
        default_dt(s, phase, record, output_dt)
        if dt is None
        else _positive("dt", dt, "a step in s")
    )
    text = _assemble(s, phase, record, t_end, dt, output_dt, release, contact_damping, offset)
    if path is not None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
        except OSError as exc:
            raise InputError(f"`out` = {str(path)!r}: cannot be written ({exc.strerror})") from None
    return text


def _header(s: Structure, phase: str, record: Record | None) -> str:
    spec = s.specimen
    source = getattr(spec, "source", "") or "not stated"
    desc = getattr(spec, "description", "")
    motion = (
        f"{record.name} ({record.source}), units {record.units} x {record.scale:g}, "
        f"dt = {record.dt:g} s, {record.npts} samples"
        if record is not None
        else "none (free vibration)"
    )
    return f'''"""OpenSeesPy model of specimen {s.name}, phase {phase}.

Phase: {PHASES[phase]}.

Specimen: {s.name}. {desc}
Source: {source}.
Ground motion: {motion}.
Exported by multimass (multimass.export.opensees).

Units: SI throughout: m, kg, s, N, rad (N m, N/m, N m/rad, Pa, kg m^2, m/s^2).
Axes: X lateral, positive towards the right pivot; Y up. theta > 0 rocks on the right
pivot (paper 001, Fig 1); OpenSees rotations are anticlockwise, so theta = -rotation.

Run it: `python model.py` builds the model, prints its modes (linear phases), runs the
analysis and writes theta.out, disp.out and accel.out here. To put the model into a
larger one, import this file and call `build(ops)` in your own domain (2-D, 3 degrees
of freedom per node); set OFFSET first if your tags collide with these.
"""
'''


def _constants(s, phase, record, t_end, dt, output_dt, offset) -> str:
    lines = [
        "# ---------------------------------------------------------------- the specimen",
        f"NAME = {s.name!r}",
        f"PHASE = {phase!r}",
        f"OFFSET = {offset}  # added to every tag below",
        f"G = {s.g!r}  # m/s^2",
        f"B = {s.B!r}  # m, half the distance between the pivots",
        f"HEIGHTS = {_script.number_list(s.H)}  # m, nodes 1..N above the base",
        f"MASSES = {_script.number_list(s.m)}  # kg, lumped at nodes 1..N",
        f"M0 = {s.m0!r}  # kg, " + ("the block" if s.is_rigid else "base (node 0)"),
        f"J0 = {s.J0!r}  # kg m^2, "
        + ("the block's" if s.is_rigid else "base")
        + " rotary inertia about its centre of mass",
        f"H0 = {s.h0!r}  # m, height of the base's centre of mass above the pivots",
    ]
    if not s.is_rigid:
        spec = s.specimen
        E, I = float(spec.E_s), float(spec.I_s)
        omega = s.full_contact_omega
        a0, a1 = s.rayleigh
        lines += [
            f"E_S = {E!r}  # Pa, Young's modulus",
            f"I_S = {I!r}  # m^4, second moment of area",
            f"K_FP = {float(spec.K_fp)!r}  # N/m, horizontal spring, base to node 1",
            f"K_ROT = {float(spec.K_rot)!r}  # N m/rad, rotational spring, base to node 1",
            f"ZETA_1, ZETA_2 = {float(spec.zeta_1)!r}, {float(spec.zeta_2)!r}  "
            "# fractions of critical, full-contact modes 1 and 2",
            "# rad/s, undamped full-contact modes 1 and 2",
            f"OMEGA_1, OMEGA_2 = {float(omega[0])!r}, {float(omega[min(1, omega.size - 1)])!r}",
            f"RAYLEIGH_A0 = {float(a0)!r}  # 1/s, C = a0 M + a1 K (multimass.model.damping)",
            f"RAYLEIGH_A1 = {float(a1)!r}  # s",
            "# axial area: inextensible in the linear phases (Y fixed); while rocking, stiff",
            f"AXIAL_AREA = {_axial_area(s)!r}  # m^2",
        ]
    lines += [
        "",
        "# ---------------------------------------------------------------- tags",
        "# OFFSET is added to each: node i (1..N) and the beam from node i to i + 1 are i",
    ]
    lines += [f"{k} = {v}" for k, v in _TAGS.items()]
    lines += ["", "# ---------------------------------------------------------------- the motion"]
    if record is not None:
        lines += [
            f"RECORD_DT = {float(record.dt)!r}  # s",
            f"RECORD_T0 = {float(record.time[0])!r}  # s, time of the first sample",
            f"RECORD_ACCEL = {_script.number_list(record.accel)}  # m/s^2",
        ]
    else:
        lines += ["RECORD_DT = None", "RECORD_T0 = 0.0", "RECORD_ACCEL = []  # no ground motion"]
    n_modes = s.n + (phase == "uplifted")
    lines += [
        f"T_END = {t_end!r}  # s, end of the analysis",
        f"DT = {dt!r}  # s, analysis step (multimass.export.default_dt)",
        f"OUTPUT_DT = {output_dt!r}  # s, recorders' step",
        f"N_MODES = {n_modes}  # modes with mass",
    ]
    return "\n".join(lines) + "\n"


def _axial_area(s: Structure) -> float:
    """Area A with E_s A / L = 1e3 x the bending stiffness 12 E_s I_s / L^3 of the shortest element."""
    if s.n < 2:
        return 1.0
    L = float(np.min(np.diff(s.H)))
    return 12e3 * float(s.specimen.I_s) / L**2


def _assemble(s, phase, record, t_end, dt, output_dt, release, contact_damping, offset) -> str:
    parts = [
        _header(s, phase, record),
        _script.IMPORTS,
        "\n# ---------------------------------------------------------------- OpenSeesPy\n"
        "# multimass.export._runtime.load_opensees, copied: the Linux wheel's bundled BLAS\n"
        "# must be loaded before OpenSeesPy imports on machines without a system BLAS.\n",
        loader_source(),
        "\n",
        _constants(s, phase, record, t_end, dt, output_dt, offset),
    ]
    if phase == "rocking":
        parts += _rocking.sections(s, release, contact_damping)
    else:
        uplifted = phase == "uplifted"
        parts += [
            _column.NODES,
            _column.ELEMENTS,
            _column.BASE_UPLIFTED if uplifted else _column.BASE_FULL,
            _column.GRAVITY if not uplifted else "",
            _column.DAMPING,
            _BUILD_LINEAR,
            _script.ANALYSIS_LINEAR,
            _REPORT_LINEAR,
        ]
    parts += [_script.GROUND_MOTION, _script.RECORDERS, _script.MAIN]
    return "\n".join(part for part in parts if part.strip()).replace("\n\n\n\n", "\n\n\n")


_BUILD_LINEAR = '''
def build(ops):
    """Add the model to the current domain (2-D, 3 dof per node); returns its node tags."""
    nodes_and_masses(ops)
    elements(ops)
    base(ops)
    gravity_terms(ops)
    damping(ops)
    return [OFFSET + i for i in range(1, len(HEIGHTS) + 1)]


def start(ops):
    """Initial state: at rest, undeformed; sets up the analysis."""
    analysis(ops)
'''

_REPORT_LINEAR = '''
def report(ops):
    """Print the undamped modes: omega^2, and f = omega / 2 pi where omega^2 > 0."""
    import math

    for k, lam in enumerate(eigenvalues(ops), start=1):
        f = f"{math.sqrt(lam) / (2 * math.pi):.6g} Hz" if lam > 0 else "unstable (rocking)"
        print(f"mode {k}: omega^2 = {lam:.9g} rad^2/s^2, {f}")
'''
