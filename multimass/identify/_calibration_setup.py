"""What `multimass.identify.calibrate` fits and what it fits it to: parameters, traces, checks.

* `Case` — one trace made ready: its channels, its segments (`segment_trace`), the
  large half-cycles and the window fitted, the first guesses of its nuisance
  parameters; `cases` checks every trace against the specimen (the checks the trace
  tools share are `multimass.identify._trace_checks`) and against what is fitted: a
  corner mean needs an impact on its corner between two large half-cycles, C_p an
  impact, and each damping ratio a mode the traces' sampling rates show.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..analysis.trace_metrics import channel_columns
from ..errors import InputError
from ..inputs.records import Record
from ..inputs.traces import Trace, read_trace
from ..modal import analyse
from ..model.structure import Structure, from_specimen
from ._trace_checks import (
    above_passband,
    check_ag,
    check_frozen,
    check_theta,
    no_rocking,
    require_sensors,
)
from .segments import segment_trace

__all__ = [
    "Case",
    "cases",
    "structure_of",
    "check_fit",
    "showable",
    "modes_shown",
    "unseen_damping",
    "window_end",
]


# ---------------------------------------------------------------------------- the traces
@dataclass(eq=False)
class Case:
    """One trace, ready to be fitted.

    Attributes
    ----------
    trace : Trace
    label : str
        Its name in results (the file's stem, made unique).
    free : bool
        A free-vibration test (no ``ag``): released at rest from θ0 at trace time τ.
    channels : tuple of str
        The channels fitted (θ first, then accelerations).
    columns : dict
        Channel → `Response.series` column (`channel_columns`).
    segments : Segments
    large : list of HalfCycle
        The half-cycles from the start whose peaks reach `theta_min` (paper 001 Sec 4.3).
    window : (float, float)
        Trace times fitted: from the first sample to the end of the last large
        half-cycle (stage 2's windows, `upto`, stop short of the impact ending it).
    idx : slice
        The samples in `window`.
    fs : float
        Sampling rate (Hz).
    theta0, tau, bias : float
        First guesses of the release angle (rad), of the trace time of the release (s;
        the trace's first time for table motion, fixed) and of θ's bias (rad).
    """

    trace: Trace
    label: str
    free: bool
    channels: tuple
    columns: dict
    segments: object
    large: list
    window: tuple
    idx: slice
    fs: float
    theta0: float = 0.0
    tau: float = 0.0
    bias: float = 0.0
    excitation_record: object = field(default=None, repr=False)
    #: Which table motion drives the model ("" the recorded ``ag``; another name a
    #: perturbed copy, `multimass.identify._calibration_input`): part of the run cache's key.
    input_tag: str = ""
    first_impact: int = 0  # index (in the trace's impacts) of the impact ending large[0]

    @property
    def n_ratios(self) -> int:
        """Impacts between two large half-cycles (each gives a peak ratio)."""
        return max(len(self.large) - 1, 0)

    @property
    def n_impacts(self) -> int:
        """Impacts that end a large half-cycle: they act inside the window (the
        Dirac-delta force before θ = 0, the filtered record around it) — the last one
        less where stage 2's window stops short of it (`upto` with a reach): only its
        force before that; its deviation then leans on its prior until the window
        grows past it."""
        return sum(1 for h in self.large if h.ends == "impact")

    @property
    def t(self) -> np.ndarray:
        return np.asarray(self.trace.time, dtype=float)

    def upto(self, k: int, reach: int = 0) -> Case:
        """The case with its first `k` large half-cycles only (a shorter window), ending
        `reach` trace samples before the impact that ends the last of them, if one does
        (`window_end`; stage 2 gives the anti-alias filter's reach)."""
        large = self.large[: max(k, 1)]
        t1 = window_end(large[-1], self.fs, reach)
        idx = slice(0, int(np.searchsorted(self.t, t1, side="right")))
        return replace(self, large=large, window=(self.window[0], float(t1)), idx=idx)

    def cut(self, t1: float) -> Case:
        """The case with its window ending at trace time `t1` (its half-cycles kept)."""
        idx = slice(0, int(np.searchsorted(self.t, t1, side="right")))
        return replace(self, window=(self.window[0], float(t1)), idx=idx)

    def excitation(self, theta0: float):
        from ..inputs.excitations import FreeRelease

        return FreeRelease(theta0=theta0) if self.free else self.excitation_record


def window_end(half, fs: float, reach: int = 0) -> float:
    """Trace time at which a window whose last half-cycle is `half` ends: the
    half-cycle's end, or, where an impact ends it, `reach` samples (at `fs`) before
    that impact — at most back to the half-cycle's start."""
    if half.ends != "impact" or reach <= 0:
        return float(half.t_stop)
    return float(max(half.t_stop - reach / fs, half.t_start))


def _load(item, g: float) -> Trace:
    if isinstance(item, Trace):
        return item
    if isinstance(item, (str, Path)):
        return read_trace(item, g=g)
    raise InputError(
        f"`traces` holds {item!r:.60}: give Trace objects (multimass.read_trace) or trace "
        "CSV file paths"
    )


def structure_of(traces: Sequence, structure, g: float = 9.81) -> tuple[Structure, list]:
    """The column tested and the traces read: `structure`, else the traces' specimen line."""
    if isinstance(traces, (Trace, str, Path)):
        traces = [traces]
    if not isinstance(traces, Sequence) or not traces:
        raise InputError(
            f"`traces` = {traces!r:.60}: give one or more traces (Trace objects or CSV paths)"
        )
    loaded = [_load(t, g) for t in traces]
    if structure is None:
        names = {t.specimen for t in loaded}
        if None in names:
            bad = next(t for t in loaded if t.specimen is None)
            raise InputError(
                f"{bad.source}: no `# specimen: NAME` line and no specimen given; give "
                "the specimen (--specimen S1, or structure='S1')"
            )
        if len(names) > 1:
            raise InputError(
                f"the traces name different specimens ({', '.join(sorted(names))}); "
                "calibrate one specimen at a time, or give it explicitly"
            )
        structure = names.pop()
    st = structure if isinstance(structure, Structure) else from_specimen(structure)
    if st.n == 0 or getattr(st.specimen, "kind", "") != "column":
        raise InputError(
            f"`structure` = {st.name!r}: calibration is for the multi-mass columns (their "
            "specimens carry restitution means and Rayleigh damping); a rigid block has "
            "neither to fit"
        )
    if abs(st.g - g) > 1e-12:  # values written in g: convert with the specimen's gravity
        loaded = [t if isinstance(t, Trace) else read_trace(t, g=st.g) for t in traces]
    return st, loaded


def _channels(trace: Trace, st: Structure, wanted) -> tuple[tuple, dict]:
    """(channels fitted, channel → column); InputError for a missing θ or sensor."""
    columns = channel_columns(trace, st)  # unknown sensors and nodes: named errors
    if "theta" not in trace.channels:
        raise InputError(
            f"{trace.source}: no `theta` column; calibration fits the base rotation and the "
            "accelerations: add a column `theta [rad]` (or `[deg]`)"
        )
    accel = [c for c in trace.names if columns[c].startswith("a") and columns[c] != "ag"]
    if wanted is not None:
        missing = [c for c in wanted if c not in trace.channels]
        if missing:
            raise InputError(
                f"{trace.source}: `channels` names {', '.join(missing)}, which the trace does "
                f"not have; its channels: {', '.join(trace.names)}"
            )
        chosen = ["theta"] + [c for c in wanted if c in accel]
    else:
        listed = ",".join(accel) if accel else "theta"
        fix = f"choose the channels to fit (channels={accel!r}, --channels {listed})"
        require_sensors(trace, st, st.specimen.sensors, fix)
        chosen = ["theta"] + accel
    return tuple(chosen), columns


def _label(trace: Trace, seen: set) -> str:
    base = Path(trace.source).stem if trace.source not in ("arrays", "text") else "trace"
    label, k = base, 2
    while label in seen:
        label, k = f"{base}_{k}", k + 1
    seen.add(label)
    return label


def _release_guess(case_t: np.ndarray, seg, first, st) -> float:
    """Trace time of the release: where θ leaves its held value, less the model's time to
    fall by the quiet band (θ0 − θ ≈ ½ (α − θ0) p² t² from rest)."""
    x = seg.smooth[first.start : first.stop] * first.sign
    k = int(np.argmax(x < x.max() - seg.band))
    drop = max(seg.band, 1e-9)
    t_drop = math.sqrt(2.0 * drop / max((st.alpha_cg - first.peak) * st.p**2, 1e-9))
    return float(max(case_t[first.start + k] - t_drop, case_t[0]))


def _large_run(seg, free: bool = True) -> tuple[list, int]:
    """The first run of consecutive large half-cycles joined by impacts (a half-cycle the
    record's end cuts short is left out: its peak is unknown), and the index of the
    impact that ends its first half-cycle."""
    half = seg.half_cycles
    i0 = next((i for i, h in enumerate(half) if not h.small), None)
    if i0 is None:
        return [], 0
    large = [half[i0]]
    while large[-1].ends == "impact" and i0 + len(large) < len(half):
        nxt = half[i0 + len(large)]
        if nxt.small or nxt.ends == "end":  # too small, or cut short by the record's end
            break
        large.append(nxt)
    if not free:  # table motion: the small half-cycles before are in the window too
        large = list(half[: i0 + len(large)])
    first_impact = sum(1 for m in seg.impacts if m.t <= large[0].t_start + 1e-12)
    return large, first_impact


def cases(loaded: list, st: Structure, fit: tuple, channels, theta_min: float) -> list[Case]:
    """Every trace checked against the specimen and made ready (`Case`), and against what
    `fit` asks for (`check_fit`)."""
    seen: set = set()
    out = []
    for trace in loaded:
        chosen, columns = _channels(trace, st, channels)
        check_theta(trace, st)
        check_frozen(trace)
        seg = segment_trace(trace, theta_min=theta_min)
        check_ag(trace, st, seg)
        free = trace.ag is None
        large, first_impact = _large_run(seg, free)
        if not large or max(h.peak for h in large) < theta_min:
            raise no_rocking(trace, seg, theta_min, "calibration fits the large half-cycles")
        if free and large[0].begins != "release":
            raise InputError(
                f"{trace.source}: the trace starts while rocking and has no `ag` channel; a "
                "free-vibration trace must start held at its release angle (record from "
                "before the release); a test with table motion needs its `ag` column"
            )
        t = np.asarray(trace.time, dtype=float)
        t1 = large[-1].t_stop
        idx = slice(0, int(np.searchsorted(t, t1, side="right")))
        record = None
        if not free:
            try:
                record = Record(
                    t - t[0], np.asarray(trace.ag), name="table (ag)", source=trace.source
                )
            except InputError as err:
                raise InputError(f"{trace.source}: the `ag` column as excitation: {err}") from None
        case = Case(
            trace=trace, label=_label(trace, seen), free=free, channels=chosen, columns=columns,
            segments=seg, large=large, window=(float(t[0]), float(t1)), idx=idx, fs=seg.fs,
            bias=float(seg.bias), excitation_record=record, first_impact=first_impact,
        )  # fmt: skip
        if free:
            first = large[0]
            case = replace(
                case,
                theta0=float(first.sign * first.peak),
                tau=_release_guess(t, seg, first, st),
            )
        else:
            case = replace(case, tau=float(t[0]))
        out.append(case)
    check_fit(out, fit, st, theta_min)
    return out


def _corner_impacts(case: Case) -> dict:
    """How many impacts on each corner join two large half-cycles of the case."""
    seen = {"right": 0, "left": 0}
    for a, b in zip(case.large, case.large[1:]):
        if a.ends == "impact" and not (a.small or b.small):
            seen["right" if b.sign > 0 else "left"] += 1
    return seen


def showable(out: list, fit, st: Structure, theta_min: float) -> tuple[tuple, dict]:
    """(the names of `fit` the traces can show, name → why not for the others): the
    default fit's check — a corner mean without an impact on its corner, C_p without an
    impact are left out (the specimen's value, said so); the damping ratios are kept
    and judged by the covariance (ill-posed where the traces do not fix them)."""
    keep, dropped = [], {}
    for name in fit:
        try:
            if name not in ("zeta1", "zeta2"):
                check_fit(out, (name,), st, theta_min)
        except InputError as err:
            dropped[name] = str(err).split("; give")[0]
            continue
        keep.append(name)
    return tuple(keep), dropped


def check_fit(out: list, fit, st: Structure, theta_min: float) -> None:
    """InputError if the traces cannot show what `fit` asks for: a corner mean without an
    impact on its corner between two large half-cycles, C_p without an impact, more
    damping ratios than the modes below the traces' anti-alias passbands."""
    per = {c.label: _corner_impacts(c) for c in out}
    for name, corner in (("r_er", "right"), ("r_el", "left")):
        if name in fit and not any(seen[corner] for seen in per.values()):
            found = "; ".join(
                f"{c.trace.source}: {sum(not h.small for h in c.large)} large half-cycle(s), "
                f"{per[c.label]['right']} right and {per[c.label]['left']} left impact(s) "
                "between them"
                for c in out
            )
            raise InputError(
                f"`fit` has {name}, the mean restitution of impacts on the {corner} corner, "
                f"but no trace has such an impact between two half-cycles of at least "
                f"theta_min = {theta_min:g} rad ({found}); give a test that rocks longer, "
                f"lower theta_min (--theta-min), or leave {name} out of `fit` (--fit)"
            )
    if "cp" in fit and not any(c.n_impacts for c in out):
        raise InputError(
            f"`fit` has cp, the Dirac-delta force of an impact, but no trace has an impact "
            f"ending a half-cycle of at least theta_min = {theta_min:g} rad; give a test that "
            "rocks longer, lower theta_min (--theta-min), or leave cp out of `fit` (--fit)"
        )
    _check_damping(out, [n for n in ("zeta1", "zeta2") if n in fit], st)


def modes_shown(out: list, st: Structure) -> tuple[set, dict]:
    """(the modes the traces show: {(Hz, "uplifted mode j")}, those they do not → why):
    the uplifted modes in the rocking, the full-contact ones with table motion or in a
    free trace's stretches of full contact, each below `PASSBAND` × the trace's rate."""
    model = analyse(st)
    shown, hidden = set(), {}
    for c in out:
        phases = [("uplifted", model.rocking)] + (
            [("full-contact", model.full_contact)] if not c.free or c.segments.full_contact else []
        )
        for label, pm in phases:
            for j, f in zip(pm.mode, pm.freq_hz):
                why = above_passband(float(f), c.fs)
                key = (float(f), f"{label} mode {int(j)}")
                if why is None:
                    shown.add(key)
                else:
                    hidden.setdefault(key, f"{c.trace.source}: {why}")
    hidden = {k: w for k, w in hidden.items() if k not in shown}
    return shown, hidden


def unseen_damping(out: list, st: Structure) -> dict:
    """Damping ratio name → why the traces do not fix it: ζ_j is the damping of mode j
    (Rayleigh's anchor: the full-contact mode j), and the traces fix it only where they
    show that mode or the uplifted mode j, the same elastic mode with the base pinned at a
    corner (`modes_shown`). Otherwise ζ_j comes from the Rayleigh form's extrapolation of
    the lower modes' decay, which the model's error decides, not the traces: S2 at
    116–126 Hz shows 5.2 and 20.5 Hz while ζ2 is set at 98 Hz, and `restitution` put ζ2
    67 %, 72 % and 13 times off with stds of 10, 18 and 2 % (coverage draws 12, 36 and 27
    of seed 0, `multimass.bench.coverage_draws`)."""
    shown, hidden = modes_shown(out, st)
    seen = ", ".join(f"{name} ({f:.4g} Hz)" for f, name in sorted(shown)) or "none"
    why = {}
    for j in (1, 2):
        if any(name.endswith(f" mode {j}") for _, name in shown):
            continue
        mine = sorted((k, w) for k, w in hidden.items() if k[1].endswith(f" mode {j}"))
        first = f"; {mine[0][0][1]} ({mine[0][0][0]:.4g} Hz) in {mine[0][1]}" if mine else ""
        why[f"zeta{j}"] = (
            f"ζ{j} is the damping of mode {j}, which the traces do not show (they show "
            f"{seen}{first})"
        )
    return why


def _check_damping(out: list, asked: list, st: Structure) -> None:
    """Rayleigh damping sets each mode's decay from ζ1 and ζ2: fitting k of them needs k
    modes that the traces show (below `PASSBAND` × their sampling rates; the uplifted
    modes in the rocking, the full-contact ones with table motion or in a free trace's
    stretches of full contact after the rocking has died out, where `multimass identify`
    finds them too)."""
    if not asked:
        return
    shown, hidden = modes_shown(out, st)
    if len(shown) >= len(asked):
        return
    seen = ", ".join(f"{name} ({f:.4g} Hz)" for f, name in sorted(shown)) or "none"
    rest = sorted(hidden.items())
    (_, name), why = rest[0] if rest else ((0.0, "mode"), "none: the model has no more modes")
    raise InputError(
        f"`fit` has {', '.join(asked)}: the Rayleigh damping ratios set the decay of the "
        f"column's modes, so fitting {len(asked)} needs {len(asked)} mode(s) the traces show, "
        f"but they show {seen}; the next, {name} in {why}; fit fewer damping ratios (--fit), "
        "or record faster"
    )
