"""What `multimass.identify.modes` fits: the sensors, the modes asked, and the samples.

* **Sensors**: the specimen's named sensors (all of them must be in the trace), or the
  ones asked, or — for a specimen without named sensors — every acceleration column.
* **Modes**: the model's underdamped modes of a phase (`multimass.modal.analyse`);
  one above `PASSBAND` × the sampling rate is not identifiable: the anti-alias filter
  of a recorder attenuates it (flat to 0.4 fs on the toolkit's synthetic recorder).
  Such a mode is listed as not identifiable when every mode is asked, and is an error
  when asked by number (`check_modes`).
* **Half-cycles** (`Segments.half_cycles` with a peak ≥ theta_min): the samples where
  ``|θ|`` ≥ `EDGE` × the half-cycle's peak, which keeps out the impacts at both ends
  (and the Dirac-delta impact force acting before them, paper 001 Eqs 14–17); a free
  release also loses the samples held at the release angle, up to where θ has left
  it by two widths of the quiet band.
* **Full contact** (`Segments.full_contact`): a free decay only once the column has
  stopped rocking, and rocking below the θ channel's noise cannot be seen in θ (on
  the synthetic S1 trace it goes on 0.7 s into the first "full contact" stretch, at
  θ < 4 mrad, with the uplifted modes ringing at 20 Hz in the accelerations). So the
  stretch is cut into windows of `FC_PERIODS` periods of its lowest mode (half
  overlapping), each fitted on its own; the decay starts at the first window whose
  residual is within `SETTLE_RATIO` of the quietest window's and white (`settled_start`);
  a stretch without such a window is left out (still rocking).
"""

from __future__ import annotations

import math

import numpy as np

from ..analysis.trace_metrics import channel_columns
from ..errors import InputError
from ..inputs.traces import Trace
from ..model.structure import Structure
from . import _modes_fit as fitting
from ._trace_checks import PASSBAND, above_passband, no_rocking, require_sensors

__all__ = [
    "PASSBAND",
    "EDGE",
    "sensor_channels",
    "model_modes",
    "check_modes",
    "half_cycle_ranges",
    "settled_start",
    "rocking_ranges",
    "contact_ranges",
]

#: Half-cycle samples kept: ``|θ|`` at least this fraction of the half-cycle's peak.
EDGE = 0.1
#: Shortest full-contact stretch fitted, and the window of its settling test, in periods
#: of its lowest mode.
FC_PERIODS = 5.0
#: A window is settled when its residual is within this factor of the quietest window's.
SETTLE_RATIO = 1.3
#: ... and its residual white: lag-1 autocorrelation within ± this.
WHITE_RHO = 0.35


def sensor_channels(trace: Trace, st: Structure, sensors=None) -> tuple[list[str], list[int]]:
    """The trace's acceleration columns to use and their 1-based nodes, by height.

    Raises
    ------
    InputError
        A named sensor of the specimen (or one asked) missing from the trace, a
        sensor unknown to the specimen, two columns at one node, fewer than two.
    """
    named = tuple(getattr(st.specimen, "sensors", ()))
    columns = {k: v for k, v in channel_columns(trace, st).items() if v not in ("theta", "ag")}
    by_node = {}
    for name, col in columns.items():
        node = int(col[1:])
        if node in by_node:
            raise InputError(
                f"{trace.source}: columns `{by_node[node]}` and `{name}` are both at node "
                f"{node}; keep one"
            )
        by_node[node] = name
    if sensors is None:
        want = [(k, n) for k, n in named] if named else [(by_node[n], n) for n in sorted(by_node)]
    else:
        want = _asked(sensors, st, named)
    present = [k for k, n in named if n in by_node] or [str(n) for n in sorted(by_node)]
    example = ",".join(present) if len(present) >= 2 else "A1,A2"
    fix = f"name the sensors to use (sensors=[...], --sensors {example})"
    require_sensors(trace, st, want, fix)
    want = sorted(want, key=lambda kn: kn[1])
    if len(want) < 2:
        raise InputError(
            f"{trace.source}: {len(want)} acceleration sensor(s); operational shapes need at "
            "least two sensors at different heights (a MAC of one value is always 1)"
        )
    return [by_node[n] for _, n in want], [n for _, n in want]


def _asked(sensors, st: Structure, named) -> list[tuple[str, int]]:
    if isinstance(sensors, (str, bytes)) or not isinstance(sensors, (list, tuple)):
        raise InputError(
            f"`sensors` = {sensors!r:.60}: give a list of sensor names (e.g. ['A2', 'A4']) "
            "or 1-based nodes (e.g. [3, 5])"
        )
    out = []
    for item in sensors:
        if isinstance(item, str):
            hit = next(((k, n) for k, n in named if k.lower() == item.strip().lower()), None)
            if hit is None:
                known = ", ".join(k for k, _ in named) or "none"
                raise InputError(
                    f"`sensors`: {st.name!r} has no sensor {item!r} (its sensors: {known}); "
                    f"or give a node number 1..{st.n}"
                )
            out.append(hit)
        elif isinstance(item, (int, np.integer)) and not isinstance(item, bool):
            if not 1 <= int(item) <= st.n:
                raise InputError(f"`sensors`: node {item} is outside 1..{st.n} of {st.name!r}")
            out.append((f"a{int(item)}", int(item)))
        else:
            raise InputError(f"`sensors`: {item!r:.40} is neither a sensor name nor a node")
    if len({n for _, n in out}) != len(out):
        raise InputError(f"`sensors` = {list(sensors)!r}: give each sensor once")
    return out


def model_modes(phase_modes, asked, fs: float):
    """(modes, freq_hz, damping, not_identifiable) of one phase of the model.

    `asked` is None (every mode) or a sequence of mode numbers. A mode is
    identifiable when it is underdamped and below `PASSBAND` × fs; the others go to
    `not_identifiable` (mode → reason).
    """
    under = {int(m): (float(f), float(z)) for m, f, z in zip(
        phase_modes.mode, phase_modes.freq_hz, phase_modes.damping
    )}  # fmt: skip
    over = {int(m): float(f) for m, f in zip(
        phase_modes.overdamped_mode, phase_modes.overdamped_freq_hz
    )}  # fmt: skip
    wanted = sorted(set(under) | set(over)) if asked is None else list(asked)
    keep, skip = [], {}
    for j in wanted:
        if j in over:
            skip[j] = f"overdamped in the model ({over[j]:.4g} Hz): no vibration to identify"
        elif j not in under:
            skip[j] = "no such mode in the model"
        elif why := above_passband(under[j][0], fs):
            skip[j] = why
        else:
            keep.append(j)
    f = np.array([under[j][0] for j in keep])
    z = np.array([under[j][1] for j in keep])
    return np.array(keep, dtype=int), f, z, skip


def check_modes(source: str, phase: str, keep, skip: dict, asked) -> None:
    """InputError if no mode of `phase` is left to identify, or if a mode asked by number
    (`asked` not None) is not identifiable (`model_modes`' `skip`): the reasons and the fix."""
    if keep.size and (asked is None or not skip):
        return
    name, other = phase.replace("_", "-"), "full_contact" if phase == "rocking" else "rocking"
    alone = (
        f"identify the {other.replace('_', '-')} modes alone (phases='{other}', --phase {other})"
    )
    if asked is None:  # every mode of the model: the lowest says why
        j, why = min(skip.items()) if skip else ("-", "the model has none")
        raise InputError(
            f"{source}: no {name} mode to identify (the lowest, mode {j}: {why}); record "
            f"faster, or {alone}"
        )
    why = "; ".join(f"mode {j}: {s}" for j, s in skip.items())
    if not keep.size:
        raise InputError(
            f"{source}: no {name} mode to identify ({why}); ask for other modes, or {alone}"
        )
    listed = ",".join(str(j) for j in keep)
    raise InputError(
        f"{source}: mode(s) {', '.join(map(str, skip))} asked cannot be identified in the "
        f"{name} phase ({why}); ask for fewer modes (modes=[{listed}], --modes {listed})"
    )


def half_cycle_ranges(seg, min_samples: int) -> tuple[list[tuple[int, int, int]], int]:
    """Sample ranges [i0, i1) of the half-cycles ≥ theta_min, trimmed (module docstring).

    Returns ([(i0, i1, half-cycle index), ...], number of large half-cycles too short).
    """
    out, short = [], 0
    for j, h in enumerate(seg.half_cycles):
        if h.small:
            continue
        x = h.sign * seg.smooth[h.start : h.stop]
        keep = np.flatnonzero(x >= EDGE * h.peak)
        if h.begins == "release" and keep.size:
            held = np.flatnonzero(x >= h.peak - 2.0 * seg.band)
            keep = keep[keep > (held.max() if held.size else -1)]
        if keep.size < min_samples:
            short += 1
            continue
        out.append((h.start + int(keep[0]), h.start + int(keep[-1]) + 1, j))
    return out, short


def settled_start(a: int, b: int, window: int, fit_of) -> int | None:
    """First sample of [a, b) from which the full-contact stretch decays freely, or None.

    `fit_of(i0, i1)` returns the `SegmentModes` of a fit over [i0, i1). A window is
    settled when (1) each sensor's residual is within `SETTLE_RATIO` of the quietest
    window's (on average over the sensors) and (2) what is left is white noise: the
    lag-1 autocorrelation of every sensor's residual within ±`WHITE_RHO` (rocking the
    θ channel cannot see leaves a slow misfit: 0.44–0.94 on the synthetic S1–S3 traces,
    against ±0.2 once at rest), unless the fit is exact (noiseless records). None when
    no window is settled.
    """
    step = max(window // 2, 1)
    starts = list(range(a, b - window + 1, step))
    if not starts:
        return None
    fits = [fit_of(i, i + window) for i in starts]
    noise = np.array([f.noise for f in fits])
    ratio = np.mean(noise / np.maximum(noise.min(axis=0), 1e-300), axis=1)
    white = np.array([np.all(np.abs(f.rho1) <= WHITE_RHO) for f in fits])
    exact = np.array([np.all(f.noise <= 1e-6 * np.maximum(f.rms, 1e-300)) for f in fits])
    ok = np.flatnonzero((ratio <= SETTLE_RATIO) & (white | exact))
    return starts[int(ok[0])] if ok.size else None


def rocking_ranges(trace, seg, f_m, K: int, min_periods: float):
    """The half-cycle ranges to fit (`half_cycle_ranges`) and what was left out."""
    large = [h for h in seg.half_cycles if not h.small]
    if not large:
        alone = (
            "identify the full-contact modes alone (phases='full_contact', --phase full_contact)"
        )
        raise no_rocking(trace, seg, seg.theta_min, "no uplifted mode can be identified", [alone])
    need = max(
        math.ceil(min_periods * seg.fs / float(f_m.min())), 2 * K + fitting.DEGREE["rocking"] + 4
    )
    ranges, short = half_cycle_ranges(seg, need)
    if not ranges:
        longest = max((h.t_stop - h.t_start for h in large), default=0.0)
        raise InputError(
            f"{trace.source}: all {len(large)} half-cycle(s) above theta_min are too short for "
            f"the modes asked: the lowest, {f_m.min():.4g} Hz, needs {need} samples "
            f"({need / seg.fs:.3g} s, min_periods = {min_periods:g} periods) of rocking away "
            f"from the impacts, the longest half-cycle lasts {longest:.3g} s; ask for higher "
            "modes only (modes=[2], --modes 2), lower min_periods, or record faster"
        )
    return ranges, {"too_short": short, "half_cycles_large": len(large)}


def contact_ranges(trace, seg, Y, f_m, z_m):
    """The settled full-contact ranges to fit (`settled_start`) and what was left out."""
    fs = seg.fs
    need = max(int(math.ceil(FC_PERIODS * fs / float(f_m.min()))), 40)
    deg = fitting.DEGREE["full_contact"]

    def fit_of(i0, i1):
        t = trace.time[i0:i1] - trace.time[i0]
        return fitting.fit_segment(t, Y[i0:i1], f_m, z_m, deg)

    ranges, settled, short, moving = [], [], 0, 0
    for a, b in seg.full_contact:
        a0 = settled_start(a, b, need, fit_of) if b - a >= need else a
        if a0 is None:
            moving += 1
        elif b - a0 < need:
            short += 1
        else:
            settled.append(round(float((a0 - a) / fs), 4))
            ranges.append((a0, b, -1))
    if not ranges:
        longest = max((b - a for a, b in seg.full_contact), default=0) / fs
        raise InputError(
            f"{trace.source}: no full-contact stretch with a free decay: the lowest "
            f"full-contact mode ({f_m.min():.4g} Hz) needs {need / fs:.3g} s "
            f"({FC_PERIODS:g} periods) at rest; of {len(seg.full_contact)} stretch(es) "
            f"where θ is quiet (longest {longest:.3g} s), {short} are shorter and {moving} "
            "still rock below the θ noise (their accelerations are no free decay); record "
            "longer after the rocking stops, or identify the uplifted modes alone "
            "(phases='rocking', --phase rocking)"
        )
    return ranges, {"too_short": short, "still_rocking": moving, "settled_s": settled}
