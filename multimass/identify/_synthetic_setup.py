"""The checked settings of `multimass.identify.synthetic_trace` and its time grids."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .. import validation as v
from ..cost import check_output, series_columns
from ..errors import InputError
from ..inputs.excitations import FreeRelease
from ..model.structure import from_specimen

__all__ = [
    "Settings", "Grids", "settings", "grids", "restitution_law", "draw_table", "with_damping",
]  # fmt: skip

#: The simulated rate must exceed this multiple of the highest full-contact frequency.
_ABOVE_MODES = 2.5


@dataclass(frozen=True)
class Settings:
    """The validated arguments of `synthetic_trace` (SI units, Hz)."""

    seed: int
    t_end: float
    fs: float
    oversample: int
    fs_in: float
    noise: float
    bias: object  # float (fraction of the peak) or dict channel -> SI value
    t_offset: float
    passband: float
    columns: dict  # trace channel -> Response.series column
    free: bool


@dataclass(frozen=True, eq=False)
class Grids:
    """Sample times: the trace's (its clock and the model's) and the simulated high-rate grid."""

    t_trace: np.ndarray
    t_model: np.ndarray
    t_high: np.ndarray
    t_simulated: float


def settings(st, excitation, t_end, seed, fs, noise, bias, t_offset, sensors, passband, oversample):
    """Validate the arguments of `synthetic_trace`; a `Settings`."""
    seed = v.integer("seed", seed, low=0)
    t_end = v.positive("t_end", t_end, "s")
    fs = v.positive("fs", fs, "Hz")
    noise = v.number("noise", noise, low=0.0, high=1.0, what="fraction of each channel's peak")
    t_offset = v.number(
        "t_offset", t_offset, low=-t_end, high=t_end, low_open=True, what="s, within ± t_end"
    )
    passband = v.number("passband", passband, low=0.1, high=0.45, what="fraction of fs")
    oversample = v.integer("oversample", oversample, low=4, high=1000)
    fs_in = oversample * fs
    f_max = float(np.max(st.full_contact_omega, initial=0.0)) / (2.0 * math.pi)
    if fs_in < _ABOVE_MODES * f_max:
        need = math.ceil(_ABOVE_MODES * f_max / fs)
        raise InputError(
            f"`oversample` = {oversample}: the response is simulated at {fs_in:g} Hz, below "
            f"{_ABOVE_MODES:g} × the highest mode of {st.name} ({f_max:.4g} Hz); "
            f"raise oversample to at least {need}"
        )
    free = isinstance(excitation, FreeRelease)
    columns = {"theta": "theta", **_sensor_columns(st, sensors)}
    if not free:
        columns["ag"] = "ag"
    # the response is simulated and kept at fs × oversample before the filter: its size
    # is known now, before the run (`multimass.cost.check_output`)
    width = series_columns(st.n) + len(columns)
    check_output(
        "`fs`",
        fs,
        (t_end + abs(t_offset)) * fs_in,
        width,
        f"the response is simulated at `fs` × oversample = {fs_in:.3g} Hz over {t_end:g} s; "
        "lower `fs` (a data logger's rate is 100–1000 Hz) or oversample (at least "
        f"{max(4, math.ceil(_ABOVE_MODES * f_max / fs))}), or shorten t_end",
    )
    return Settings(
        seed, t_end, fs, oversample, fs_in, noise, _bias(bias, columns), t_offset, passband,
        columns, free,
    )  # fmt: skip


def _sensor_columns(st, sensors) -> dict:
    """Trace channel → series column of the accelerometers recorded."""
    named = tuple(getattr(st.specimen, "sensors", ()))
    if sensors is None:
        if named:
            return {f"a_{name}": f"a{node}" for name, node in named}
        return {f"a{k}": f"a{k}" for k in range(1, st.n + 1)}
    if isinstance(sensors, (str, bytes)) or not isinstance(sensors, (list, tuple)):
        raise InputError(
            f"`sensors` = {sensors!r:.60}: give a list of sensor names (e.g. ['A2', 'A4']) "
            "or 1-based nodes (e.g. [3, 5])"
        )
    if sensors and st.n == 0:
        raise InputError(
            f"`sensors` = {sensors!r:.60}: {st.name!r} is a rigid block without elastic "
            "nodes; give sensors=None (θ only)"
        )
    out = {}
    for item in sensors:
        if isinstance(item, str):
            match = next(((k, n) for k, n in named if k.lower() == item.lower()), None)
            if match is None:
                known = ", ".join(k for k, _ in named) or "none"
                raise InputError(
                    f"`sensors`: {st.name!r} has no sensor {item!r} (its sensors: {known}); "
                    f"or give a node number 1..{st.n}"
                )
            name, column = f"a_{match[0]}", f"a{match[1]}"
        else:
            node = v.integer("sensors[...]", item, low=1, high=st.n, what="a 1-based node")
            name, column = f"a{node}", f"a{node}"
        if name in out:
            raise InputError(f"`sensors`: {item!r} is given twice; give each sensor once")
        out[name] = column
    return out


def _bias(bias, columns: dict):
    """A fraction of the peak in [0, 1], or channel → bias (SI) for known channels."""
    if not isinstance(bias, Mapping):
        return v.number("bias", bias, low=0.0, high=1.0, what="fraction of each channel's peak")
    out = {}
    for name, value in bias.items():
        if name not in columns:
            raise InputError(
                f"`bias`: unknown channel {name!r}; the trace's channels are {', '.join(columns)}"
            )
        out[name] = v.number(f"bias[{name!r}]", value, what="SI units: rad or m/s2")
    return out


def grids(cfg: Settings, half: int) -> Grids:
    """The trace's samples ``j / fs`` (its clock), the model times ``j / fs − t_offset``,
    and the simulated grid ``k / fs_in`` that covers them with `half` + 4 samples on
    each side for the filter."""
    n = math.floor((cfg.t_end + cfg.t_offset) * cfg.fs + 1e-9)
    if n < 1:
        raise InputError(
            f"`t_offset` = {cfg.t_offset:g} s with `t_end` = {cfg.t_end:g} s leaves fewer "
            "than 2 samples in the trace; raise t_end or t_offset"
        )
    t_trace = np.arange(n + 1) / cfg.fs
    t_model = t_trace - cfg.t_offset
    pad = (half + 4) / cfg.fs_in
    k_lo = math.floor((t_model[0] - pad) * cfg.fs_in)
    k_hi = math.ceil((t_model[-1] + pad) * cfg.fs_in)
    dt = 1.0 / cfg.fs_in  # the recorder's output grid is k × dt
    t_high = np.arange(k_lo, k_hi + 1) * dt
    return Grids(t_trace, t_model, t_high, float(t_high[-1] + 2.0 * dt))


def restitution_law(st, means, spread) -> tuple[tuple[float, float], float]:
    """((r̄_er, r̄_el), σ): as given, else the specimen's (paper 001, Table 1)."""
    spec = st.specimen
    if means is None:
        means = (getattr(spec, "r_right", None), getattr(spec, "r_left", None))
        if None in means:
            raise InputError(
                f"{st.name!r} has no corner means of restitution; give "
                "restitution_means=(r_right, r_left)"
            )
    elif isinstance(means, (str, bytes)) or not isinstance(means, (list, tuple)) or len(means) != 2:
        raise InputError(
            f"`restitution_means` = {means!r:.60}: give the pair (r_right, r_left), e.g. (0.93, 0.87)"
        )
    pair = tuple(
        v.number(f"restitution_means[{i}]", r, low=0.0, high=1.0, low_open=True, what="in (0, 1]")
        for i, r in enumerate(means)
    )
    if spread is None:
        spread = getattr(spec, "sigma_r", None)
        if spread is None:
            raise InputError(f"{st.name!r} has no σ_r; give restitution_spread (e.g. 0.025)")
    spread = v.number("restitution_spread", spread, low=0.0, high=0.5, what="a standard deviation")
    return pair, spread


def draw_table(rng, mean: float, spread: float, n: int) -> np.ndarray:
    """`n` values of N(mean, spread) truncated to (0, 1] (values outside are redrawn)."""
    x = rng.normal(mean, spread, n)
    for _ in range(1000):  # mean in (0, 1]: each redraw keeps at least half
        bad = (x <= 0.0) | (x > 1.0)
        if not bad.any():
            break
        x[bad] = rng.normal(mean, spread, int(bad.sum()))
    return np.clip(x, np.nextafter(0.0, 1.0), 1.0)


def with_damping(st, damping):
    """`st`, or the same column with the Rayleigh damping ratios (ζ1, ζ2) = `damping`."""
    if damping is None:
        return st
    if (
        isinstance(damping, (str, bytes))
        or not isinstance(damping, (list, tuple))
        or len(damping) != 2
    ):
        raise InputError(
            f"`damping` = {damping!r:.60}: give the pair (zeta_1, zeta_2) of fractions of "
            "critical, e.g. (0.005, 0.015)"
        )
    if st.n == 0 or not hasattr(st.specimen, "zeta_1"):
        raise InputError(
            f"`damping` = {damping!r:.60}: {st.name!r} is a rigid block without elastic modes; "
            "remove it"
        )
    z1, z2 = (
        v.number(f"damping[{i}]", z, low=0.0, high=1.0, high_open=True, what="fraction of critical")
        for i, z in enumerate(damping)
    )
    return from_specimen(dataclasses.replace(st.specimen, zeta_1=z1, zeta_2=z2))
