"""What the trace tools check in a trace before computing, one wording per check.

`restitution`, `operational_modes` and `calibrate` refuse bad input with a named error
that says the field, the value found and the fix. Each check lives in one place:

* `multimass.inputs.traces` (every use of a trace): units in the header, finite samples (NaN
  names the column and its first row), strictly increasing time;
* `multimass.identify.segments.segment_trace` (every tool cuts its trace there): a θ
  column, uniform sampling, a rate fast enough for θ's low-pass;
* here, the trace against the specimen and what is asked of it:

  - `require_sensors` — the specimen's sensors present (`operational_modes`,
    `calibrate`; `restitution` fits θ alone and needs none);
  - `no_rocking` — no half-cycle reaches theta_min (`operational_modes`, `calibrate`;
    `restitution` words its own alike);
  - `above_passband` — a mode the sampling rate cannot show (`operational_modes`'
    modes, `calibrate`'s damping ratios);
  - `check_ag` — the table acceleration in a plausible unit (all three);
  - `check_frozen` — no tail where the logger held its last value (all three);
  - `check_theta` — θ within the specimen's overturning angle α_cg: degrees under a
    ``[rad]`` header are named (all three).
"""

from __future__ import annotations

import math

import numpy as np

from ..analysis.trace_metrics import channel_columns
from ..errors import InputError
from ..inputs.traces import Trace
from ..model.structure import Structure
from .segments import Segments

__all__ = [
    "PASSBAND",
    "AG_MAX_G",
    "AG_MIN_SHARE",
    "AG_MIN_GAIN",
    "above_passband",
    "require_sensors",
    "no_rocking",
    "check_ag",
    "check_frozen",
    "check_theta",
    "FROZEN_MIN_S",
]

#: Modes above this fraction of the sampling rate are not identifiable: a recorder's
#: anti-alias filter attenuates them (flat to 0.4 fs on the toolkit's synthetic recorder).
PASSBAND = 0.4
#: Largest table acceleration believed (in g): above, the values were almost surely
#: written in m/s² under a `g` header.
AG_MAX_G = 3.0
#: A table that rocks the column reaches at least this share of g tan α_cg (the rigid
#: column's uplift; a flexible one uplifts earlier, but not at a quarter of it): below,
#: the values were almost surely written in g under an `m/s2` header.
AG_MIN_SHARE = 0.25
#: The lowest sensor's total acceleration against ``ag`` (least-squares gain over the
#: trace) is at least this when both are in their written units: the base moves with the
#: table. Measured on 86 synthetic S1–S3 table tests (sine and cosine pulses of 0.2–0.8 g,
#: 6–60 rad/s, up to 0.4 rad of rocking): 0.51–1.10; ``ag`` in m/s² under a `g` header
#: divides it by 9.81.
AG_MIN_GAIN = 1.0 / 3.0
_UNIT_RATIO = 9.81  # m/s² per g, near enough to name the likely unit
#: A tail this long (s, and at least `_FROZEN_MIN_SAMPLES` samples) in which every channel
#: repeats its value to the bit is a logger that held its last value: a sensor's noise
#: (and a column's motion, even at rest: the accelerometers ring down) changes some
#: channel at every sample of a real recording.
FROZEN_MIN_S = 1.0
_FROZEN_MIN_SAMPLES = 20


def above_passband(freq_hz: float, fs: float) -> str | None:
    """Why a mode of `freq_hz` (Hz) cannot be identified from samples at `fs` (Hz), with the
    fix; None if it can (at or below `PASSBAND` × fs)."""
    if freq_hz <= PASSBAND * fs:
        return None
    return (
        f"{freq_hz:.4g} Hz in the model, above {PASSBAND:g} × the sampling rate {fs:g} Hz = "
        f"{PASSBAND * fs:.4g} Hz (the anti-alias passband; Nyquist frequency {fs / 2:g} Hz): "
        f"not identifiable; record at {math.ceil(freq_hz / PASSBAND)} Hz or more"
    )


def require_sensors(trace: Trace, st: Structure, want, fix: str) -> None:
    """InputError unless every sensor of `want` has a column in the trace.

    Parameters
    ----------
    want : sequence of (str, int)
        (label, 1-based node): a sensor name of the specimen or ``"a<k>"`` for a node.
    fix : str
        What to do instead of adding the columns (the tool's option to choose sensors).
    """
    columns = channel_columns(trace, st)
    have = {int(c[1:]) for c in columns.values() if c not in ("theta", "ag")}
    missing = [(k, n) for k, n in want if n not in have]
    if not missing:
        return
    named = tuple(getattr(st.specimen, "sensors", ()))
    labels = {k for k, _ in named}
    cols = ", ".join(f"a_{k}" if k in labels else k for k, _ in missing)
    table = (
        f"; {st.name!r} names {', '.join(k for k, _ in named)} in its [sensors] table"
        if named
        else ""
    )
    raise InputError(
        f"{trace.source}: no column for sensor(s) {', '.join(k for k, _ in missing)} of "
        f"{st.name!r} ({cols} missing; the trace has {', '.join(trace.names)}){table}: "
        f"add the missing column(s), or {fix}"
    )


def no_rocking(trace: Trace, seg: Segments, theta_min: float, purpose: str, other=()) -> InputError:
    """The error for a trace without a half-cycle of at least `theta_min` (rad).

    `purpose` says what needs the rocking; `other` holds the tool's other fixes.
    """
    top = max((h.peak for h in seg.half_cycles), default=0.0)
    fixes = (
        ["give a test that rocks more", f"lower theta_min below {top:.3g} rad (--theta-min)"]
        if top > 0.0
        else ["give a test that rocks (θ stays within its noise: the column never uplifted)"]
    ) + list(other)
    fix = ", ".join(fixes[:-1]) + ", or " + fixes[-1] if len(fixes) > 1 else fixes[0]
    return InputError(
        f"{trace.source}: no rocking half-cycle reaches theta_min = {theta_min:g} rad "
        f"(largest {top:.3g} rad, θ noise {seg.noise:.2g} rad); {purpose}: {fix}"
    )


def _lowest_sensor(trace: Trace, st: Structure) -> str | None:
    """The acceleration column at the lowest node (None without one)."""
    columns = channel_columns(trace, st)
    accel = [(int(c[1:]), k) for k, c in columns.items() if c not in ("theta", "ag")]
    return min(accel)[1] if accel else None


def check_ag(trace: Trace, st: Structure, seg: Segments) -> None:
    """InputError if the table acceleration ``ag`` is in an implausible unit.

    Three checks, in order: its peak beyond `AG_MAX_G` g (m/s² under a `g` header); the
    column rocks (a half-cycle ≥ theta_min of `seg`, the trace's segments) under a table
    peak below `AG_MIN_SHARE` × g tan α_cg (g under an `m/s2` header, or a free-vibration
    test with a table channel); a table that moves (peak ≥ `AG_MIN_SHARE` × g tan α_cg)
    with the lowest sensor measuring less than `AG_MIN_GAIN` of it (m/s² under a `g`
    header below 3 g). Nothing to check without ``ag``.
    """
    ag = trace.ag
    if ag is None:
        return
    name = next(k for k in trace.names if k.lower() == "ag")
    where = f"{trace.source}, column `{name}` [{trace.units.get(name, '?')}]"
    g, peak = st.g, float(np.max(np.abs(ag)))
    as_mps2 = (
        f"the values look like they are in m/s2 under a `g` header ({peak / g / _UNIT_RATIO:.3g} "
        f"g if so): write it as `{name} [m/s2]`"
    )
    if peak > AG_MAX_G * g:
        raise InputError(
            f"{where}: the table acceleration peaks at {peak / g:.3g} g, beyond any "
            f"shake-table test ({AG_MAX_G:g} g): {as_mps2}"
        )
    large = [h.peak for h in seg.half_cycles if not h.small]
    uplift = g * math.tan(st.alpha_cg)  # the rigid column uplifts at g tan α (Housner)
    if peak < AG_MIN_SHARE * uplift:
        if large:
            raise InputError(
                f"{where}: the table acceleration peaks at {peak:.3g} m/s2, under "
                f"{AG_MIN_SHARE:.0%} of what uplifts {st.name!r} (g tan α_cg = {uplift:.3g} "
                f"m/s2), yet θ rocks to {max(large):.3g} rad: the values look like they are "
                f"in g under an `m/s2` header ({peak * _UNIT_RATIO:.3g} m/s2 if so): write it "
                f"as `{name} [g]`, or, for a free-vibration test, remove the `{name}` column"
            )
        return  # a table too still to judge its unit by the sensors
    low = _lowest_sensor(trace, st)
    if low is None:
        return
    a0 = np.asarray(trace.channels[low], dtype=float)
    a0, ag0 = a0 - a0.mean(), ag - ag.mean()
    gain = float(a0 @ ag0 / (ag0 @ ag0))
    if gain >= AG_MIN_GAIN:
        return
    raise InputError(
        f"{where}: the lowest sensor `{low}` [{trace.units.get(low, '?')}] measures "
        f"{gain:.3g} × the table acceleration (least squares over the trace; 0.5–1.1 when "
        "both units are right: the base moves with the table), which peaks at "
        f"{peak / g:.3g} g: {as_mps2} (or fix the sensors' unit)"
    )


def check_frozen(trace: Trace) -> None:
    """InputError if every channel of the trace stays constant to the bit from some time
    to its end for at least `FROZEN_MIN_S` (the logger held its last value): the model
    would be fitted to a column frozen in mid-air. A trace constant from its first
    sample is no hold (the tools say it does not rock)."""
    Y = np.column_stack([np.asarray(trace.channels[k], dtype=float) for k in trace.names])
    moved = np.flatnonzero(np.any(Y[1:] != Y[:-1], axis=1))
    if moved.size == 0:
        return
    k = int(moved[-1]) + 1  # the first sample of the frozen tail
    t = np.asarray(trace.time, dtype=float)
    n, span = t.size - 1 - k, float(t[-1] - t[k])
    if n < _FROZEN_MIN_SAMPLES or span < FROZEN_MIN_S:
        return
    raise InputError(
        f"{trace.source}: every channel ({', '.join(trace.names)}) is frozen from t = "
        f"{t[k]:.6g} s to the end ({span:.4g} s, {n} samples, each constant to the bit): "
        f"the logger held its last value; crop the trace at t = {t[k]:.6g} s"
    )


def check_theta(trace: Trace, st: Structure) -> None:
    """InputError if ``|θ|`` reaches the specimen's overturning angle α_cg while the trace
    goes on: the θ column is in another unit (degrees under a ``[rad]`` header are named)
    or belongs to another structure."""
    th = trace.channels.get("theta")
    if th is None:
        return  # segment_trace names a missing θ
    th = np.asarray(th, dtype=float)
    k = int(np.argmax(np.abs(th)))
    peak, alpha = abs(float(th[k])), float(st.alpha_cg)
    if peak < alpha:
        return
    name = next(c for c in trace.names if c.lower() == "theta")
    unit = trace.units.get(name, "?")
    if math.radians(peak) < alpha and unit == "rad":
        fix = (
            f"the values look like degrees under a `[rad]` header ({math.radians(peak):.3g} "
            f"rad if so): write the column as `{name} [deg]`"
        )
    else:
        fix = f"check the column's unit and that the trace is of {st.name!r}"
    raise InputError(
        f"{trace.source}, column `{name}` [{unit}]: |θ| reaches {peak:.4g} rad at t = "
        f"{float(trace.time[k]):.6g} s, beyond the overturning angle of {st.name!r} "
        f"(α_cg = {alpha:.4g} rad), yet the trace goes on: {fix}"
    )
