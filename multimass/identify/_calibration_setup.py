"""What `multimass.identify.calibrate` fits and what it fits it to: parameters, traces, checks.

* `Case` — one trace made ready: its channels, its segments (`segment_trace`), the
  large half-cycles and the window fitted, the first guesses of its nuisance
  parameters; `cases` checks every trace against the specimen.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..records import Record
from ..structure import Structure, from_specimen
from ..trace_metrics import channel_columns
from ..traces import Trace, read_trace
from .segments import segment_trace

__all__ = ["Case", "cases", "structure_of", "AG_MAX_G", "AG_MIN_SHARE"]

#: Largest table acceleration believed (in g): a shake-table record above this was
#: almost surely written in m/s² under a `g` header.
AG_MAX_G = 3.0
#: A table that rocks the column reaches at least this share of g tan α_cg (the rigid
#: column's uplift; a flexible one uplifts earlier, but not at a tenth of it): below,
#: the values were almost surely written in g under an `m/s2` header.
AG_MIN_SHARE = 0.25


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
        Trace times fitted in stage 2: from the first sample to the end of the last
        large half-cycle.
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
    first_impact: int = 0  # index (in the trace's impacts) of the impact ending large[0]

    @property
    def n_ratios(self) -> int:
        """Impacts between two large half-cycles (each gives a peak ratio)."""
        return max(len(self.large) - 1, 0)

    @property
    def n_impacts(self) -> int:
        """Impacts that end a large half-cycle: they act inside the window (the
        Dirac-delta force before θ = 0, the filtered record around it)."""
        return sum(1 for h in self.large if h.ends == "impact")

    @property
    def t(self) -> np.ndarray:
        return np.asarray(self.trace.time, dtype=float)

    def upto(self, k: int) -> Case:
        """The case with its first `k` large half-cycles only (a shorter window)."""
        if k >= len(self.large):
            return self
        large = self.large[: max(k, 1)]
        t1 = large[-1].t_stop
        idx = slice(0, int(np.searchsorted(self.t, t1, side="right")))
        return replace(self, large=large, window=(self.window[0], float(t1)), idx=idx)

    def cut(self, t1: float) -> Case:
        """The case with its window ending at trace time `t1` (its half-cycles kept)."""
        idx = slice(0, int(np.searchsorted(self.t, t1, side="right")))
        return replace(self, window=(self.window[0], float(t1)), idx=idx)

    def excitation(self, theta0: float):
        from ..excitations import FreeRelease

        return FreeRelease(theta0=theta0) if self.free else self.excitation_record


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
        sensors = [name for name, _ in st.specimen.sensors]
        have = {c[2:].lower() for c in accel if c.lower().startswith("a_")}
        lacking = [s for s in sensors if s.lower() not in have]
        if lacking:
            raise InputError(
                f"{trace.source}: the trace has no column for sensor(s) "
                f"{', '.join(lacking)}, which specimen {st.name!r} names in its [sensors] "
                f"table; add the columns (a_{lacking[0]} [g], ...) or choose the channels "
                f"to fit (channels=('theta', ...), --channels theta,a_A2)"
            )
        chosen = ["theta"] + accel
    return tuple(chosen), columns


def _check_ag(trace: Trace, st: Structure) -> None:
    """The table acceleration must be plausible: a wrong unit shows as ×9.81 or ÷9.81."""
    ag = trace.ag
    peak = float(np.max(np.abs(ag)))
    g = st.g
    unit = trace.units.get("ag", "?")
    if peak > AG_MAX_G * g:
        raise InputError(
            f"{trace.source}, column `ag`: the table acceleration peaks at {peak / g:.3g} g "
            f"(written in {unit}), beyond any shake-table test ({AG_MAX_G:g} g); were the "
            "values written in m/s2 under a `g` header? Fix the unit in the header"
        )
    needed = g * math.tan(st.alpha_cg)  # uplift of the rigid column (Housner): g tan α
    if peak < AG_MIN_SHARE * needed:
        raise InputError(
            f"{trace.source}, column `ag`: the table acceleration peaks at {peak:.3g} m/s2 "
            f"(written in {unit}), under {AG_MIN_SHARE:.0%} of what uplifts {st.name!r} (g tan α_cg = "
            f"{needed:.3g} m/s2), yet the trace rocks; were the values written in g under "
            "an `m/s2` header? Fix the unit in the header"
        )


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
    """Every trace checked against the specimen and made ready (`Case`)."""
    seen: set = set()
    out = []
    for trace in loaded:
        chosen, columns = _channels(trace, st, channels)
        seg = segment_trace(trace, theta_min=theta_min)
        free = trace.ag is None
        large, first_impact = _large_run(seg, free)
        top = max((h.peak for h in seg.half_cycles), default=0.0)
        if not large or max(h.peak for h in large) < theta_min:
            raise InputError(
                f"{trace.source}: no rocking: no half-cycle reaches theta_min = "
                f"{theta_min:g} rad (largest {top:.3g} rad; θ noise {seg.noise:.2g} rad); "
                "calibration needs a test that rocks: give a trace with rocking, or lower "
                "theta_min"
            )
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
            _check_ag(trace, st)
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
    return out
