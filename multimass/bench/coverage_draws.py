"""The hidden parameters of the identification coverage benchmark, and their traces.

Each synthetic test of `multimass.bench.coverage` is drawn away from its specimen file,
so that an estimator that assumes the file's values is seen to do so:

* C_p of the Dirac-delta force: Table 2's (paper 001; 1750 kg m/rad/s for "DD") times
  U(0.6, 1.4);
* the damping ratios ζ1, ζ2: the specimen's times U(0.5, 1.5) each;
* restitution: corner means the specimen's r̄_er, r̄_el plus U(−0.03, 0.03) (at most
  0.99), and per-impact coefficients drawn about them with σ_r ~ U(0.01, 0.04)
  (`multimass.identify.synthetic_trace`);
* the test: a free release from θ0 ~ U(0.05, 0.15) rad (10 s), or, for every
  `TABLE_EVERY`-th case, table motion: a window of a real record (the ``ag`` channel);
* the recorder: sampling rate log-uniform in 100–1000 Hz, white noise U(1 %, 5 %) of
  each channel's peak, a bias per channel uniform in ± U(0.2 %, 2 %) of its peak, and
  a clock offset (trace time of the model's t = 0) ~ U(0.005, 0.3) s.

The record window: `WINDOW` s of the record starting U(0.5, 3) s before its peak,
cosine-tapered over `TAPER` s at both ends, scaled so that its peak is U(1.2, 2.5)
times the uplift threshold of the column rocking as a rigid body, g tan α_cg (paper
001's α_cg), then `FREE_AFTER` s of free rocking. A window that overturns the column
is scaled by 0.7 and run again (at most 4 times).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..identify import synthetic_trace
from ..impact_models.table2 import IMPACT_MODELS
from ..inputs.excitations import FreeRelease
from ..inputs.records import Record, read_record
from ..model.structure import from_specimen

__all__ = [
    "Draw",
    "RANGES",
    "RECORDS",
    "TABLE_EVERY",
    "draw_case",
    "make_trace",
    "record_window",
]

#: The ranges the hidden parameters are drawn from (see the module docstring).
RANGES = {
    "cp_ratio": (0.6, 1.4),
    "zeta_ratio": (0.5, 1.5),
    "mean_shift": (-0.03, 0.03),
    "mean_max": 0.99,
    "sigma_r": (0.01, 0.04),
    "theta0": (0.05, 0.15),
    "fs": (100.0, 1000.0),
    "noise": (0.01, 0.05),
    "bias": (0.002, 0.02),
    "t_offset": (0.005, 0.3),
    "pga_over_uplift": (1.2, 2.5),
}
#: Every this-many-th case of a specimen (index % TABLE_EVERY == TABLE_EVERY − 1) is
#: table motion when records are given.
TABLE_EVERY = 5
#: Record files (in the records folder) and their units (the folder's README).
RECORDS = {
    "elcentro_1940_NS.dat": "g",
    "kobe_1995.dat": "m/s2",
    "northridge_1994.dat": "m/s2",
    "loma_prieta_1989.dat": "m/s2",
}
WINDOW = 5.0  # s of record
TAPER = 0.3  # s, cosine taper at both ends of the window
FREE_AFTER = 4.0  # s of free rocking after the window
FREE_T_END = 10.0  # s, a free-vibration test
_SIM_RATE = 8000.0  # Hz: the synthetic recorder's simulated rate (synthetic_trace's default)
_SPECIMEN_KEY = {"S1": 1, "S2": 2, "S3": 3}


@dataclass(frozen=True)
class Draw:
    """The hidden parameters of one synthetic test (SI units, rad, Hz)."""

    specimen: str
    index: int
    seed: int
    family: str
    kind: str  # "free" or "table"
    cp: float | None
    cp_table: float | None
    zeta1: float
    zeta2: float
    r_right: float
    r_left: float
    sigma_r: float
    theta0: float | None
    fs: float
    noise: float
    bias: float
    t_offset: float
    record: str | None = None
    record_start: float | None = None
    pga_over_uplift: float | None = None

    @property
    def case(self) -> str:
        """The case's name, e.g. ``S1-007``."""
        return f"{self.specimen}-{self.index:03d}"

    def to_dict(self) -> dict:
        return {"case": self.case, **asdict(self)}


def draw_case(
    specimen: str, index: int, seed: int = 0, family: str = "DD", records: bool = True
) -> Draw:
    """The hidden parameters of case `index` of `specimen` (reproducible from `seed`).

    Parameters
    ----------
    specimen : str
        A bundled column ("S1", "S2", "S3") or another column specimen's name.
    index : int
        The case's number (≥ 0); every `TABLE_EVERY`-th is table motion if `records`.
    seed : int
        The benchmark's seed; with the specimen and the index it seeds every draw.
    family : str
        The impact model simulated: "DD" (Dirac-delta, C_p drawn) or "CIM".
    records : bool
        Whether table-motion cases are drawn (they need the record files).
    """
    if family not in ("DD", "CIM"):
        raise InputError(f"`family` = {family!r}: give DD (Dirac-delta) or CIM")
    st = from_specimen(specimen)
    spec = st.specimen
    key = _SPECIMEN_KEY.get(st.name, sum(st.name.encode()))
    rng = np.random.default_rng([int(seed), key, int(index)])
    u = lambda name: float(rng.uniform(*RANGES[name]))  # noqa: E731
    cp_table = IMPACT_MODELS[family][2]
    cp = cp_table * u("cp_ratio") if cp_table is not None else None
    zeta1, zeta2 = spec.zeta_1 * u("zeta_ratio"), spec.zeta_2 * u("zeta_ratio")
    r_right = min(spec.r_right + u("mean_shift"), RANGES["mean_max"])
    r_left = min(spec.r_left + u("mean_shift"), RANGES["mean_max"])
    sigma_r = u("sigma_r")
    theta0 = u("theta0")
    lo, hi = RANGES["fs"]
    fs = float(round(math.exp(rng.uniform(math.log(lo), math.log(hi)))))
    noise, bias, t_offset = u("noise"), u("bias"), u("t_offset")
    table = records and index % TABLE_EVERY == TABLE_EVERY - 1
    names = sorted(RECORDS)
    extra = {}
    if table:
        extra = {
            "record": names[int(rng.integers(len(names)))],
            "record_start": float(rng.uniform(0.5, 3.0)),  # s before the record's peak
            "pga_over_uplift": u("pga_over_uplift"),
        }
    return Draw(
        specimen=st.name, index=int(index), seed=int(seed), family=family,
        kind="table" if table else "free", cp=cp, cp_table=cp_table, zeta1=zeta1,
        zeta2=zeta2, r_right=r_right, r_left=r_left, sigma_r=sigma_r,
        theta0=None if table else theta0, fs=fs, noise=noise, bias=bias,
        t_offset=t_offset, **extra,
    )  # fmt: skip


def record_window(path, units: str, before_peak: float, peak: float) -> Record:
    """`WINDOW` s of a record starting `before_peak` s before its largest ``|ü_g|``, tapered
    over `TAPER` s at both ends, starting at t = 0 and scaled to the peak `peak` (m/s²)."""
    rec = read_record(path, units=units)
    t, a = np.asarray(rec.time), np.asarray(rec.accel)
    t_peak = float(t[int(np.argmax(np.abs(a)))])
    t0 = max(float(t[0]), t_peak - before_peak)
    keep = (t >= t0) & (t <= t0 + WINDOW)
    tw, aw = t[keep] - t[keep][0], a[keep].copy()
    ramp = np.clip(np.minimum(tw, tw[-1] - tw) / TAPER, 0.0, 1.0)
    aw *= 0.5 * (1.0 - np.cos(np.pi * ramp))  # cosine taper
    scale = peak / float(np.max(np.abs(aw)))
    name = f"{Path(path).stem} [{t0:.2f}, {t0 + WINDOW:.2f}] s x {scale:.3g}"
    return Record.from_arrays(tw, aw, "m/s2", scale=scale, name=name, source=str(path))


def make_trace(draw: Draw, records_dir=None):
    """The synthetic trace of `draw` (a `multimass.identify.SyntheticTrace`), and the
    number of times its record window was scaled down to keep the column standing."""
    st = from_specimen(draw.specimen)
    oversample = max(4, math.ceil(_SIM_RATE / draw.fs))
    common = dict(
        seed=1000 * draw.seed + draw.index, fs=draw.fs, noise=draw.noise, bias=draw.bias,
        t_offset=draw.t_offset, restitution_means=(draw.r_right, draw.r_left),
        restitution_spread=draw.sigma_r, C_p=draw.cp, damping=(draw.zeta1, draw.zeta2),
        oversample=oversample,
    )  # fmt: skip
    if draw.kind == "free":
        excitation = FreeRelease(theta0=draw.theta0)
        return synthetic_trace(st, excitation, draw.family, FREE_T_END, **common), 0
    if records_dir is None:
        raise InputError(f"case {draw.case} is table motion: give the records folder")
    path = Path(records_dir) / draw.record
    peak = draw.pga_over_uplift * st.g * math.tan(st.alpha_cg)
    for shrink in range(4):
        rec = record_window(path, RECORDS[draw.record], draw.record_start, peak * 0.7**shrink)
        try:
            trace = synthetic_trace(st, rec, draw.family, WINDOW + FREE_AFTER, **common)
        except InputError as err:
            if "overturned" not in str(err) or shrink == 3:
                raise
            continue
        return trace, shrink
    raise AssertionError("unreachable")
