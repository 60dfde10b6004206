"""A suite: one structure, many ground motions at many intensities, Monte-Carlo restitution.

A `Suite` is built in Python or read from TOML (`Suite.from_toml`)::

    name = "B6M under near-fault pulses"
    [structure]
    specimen = "B6M"                  # bundled name, or a specimen TOML path
    [model]                           # optional
    impact = "CIM"                    # CIM (blocks) | DD1 … DD5 | DD (columns)
    restitution = "modified"          # modified | housner | a value | Table 2's (omit)
    t_free_s = 5.0                    # free response after the motion (s)
    method = "auto"                   # | DOP853 | exponential (a column's rocking phases;
                                      #   multimass.sweeps.method_choice; auto by default)
    [monte_carlo]
    draws = 50                        # runs per motion and level
    seed = 1
    k = { distribution = "uniform", low = 0.5, high = 1.0 }   # η_M's k, drawn per run
    [intensity]
    measure = "amp_over_g_tan_alpha"  # | pga | pgv | pgd | arias | sa | scale
    levels = { start = 0.5, stop = 6.0, count = 12 }          # or a list
    unit = "1"                        # g | m/s2 | m/s | m | 1 (the measure's)
    [pulses]                          # Mavroeidis & Papageorgiou (2003) pulses
    omega_p_over_p = { start = 1, stop = 10, count = 10 }
    gamma = 2.0                       # or a list
    nu_rad = 0.0                      # or a list
    [[records]]                       # and/or recorded motions
    path = "records/elcentro_1940_NS.dat"   # relative to the suite file
    units = "g"                       # two-column files; .AT2 headers give theirs

Every key names its unit; unknown keys are errors that list the allowed ones. Checks
made here, before any run: each record readable and plausible in its stated units (a PGA
between 0.005 g and 3 g; records whose PGAs differ by more than 100× are refused as a
unit mix), Sa only at periods the records resolve (T ≥ 2·dt, `multimass.analysis.intensity`),
no level that needs a record scaled by more than `max_scale` (default 10), at least one
motion, at least one level.

`multimass.suites.runs.run_suite` runs the suite; `multimass.suites.analysis` fits the
fragility curves.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import validation as v
from ..errors import InputError
from ..inputs.excitations import MP_MAX_GAMMA, MPShape
from ..inputs.records import Record, read_record
from ..inputs.units import G
from ..model.structure import Structure, from_specimen

__all__ = [
    "Suite",
    "Distribution",
    "PulseSet",
    "MEASURES",
    "MEASURE_UNITS",
    "MAX_SCALE",
]

#: Intensity measures a suite can scale to, and the units their levels may be given in.
MEASURE_UNITS = {
    "pga": ("g", "m/s2"),
    "pgv": ("m/s",),
    "pgd": ("m",),
    "arias": ("m/s",),
    "sa": ("g", "m/s2"),
    "scale": ("1",),
    "amp_over_g_tan_alpha": ("1",),
}
MEASURES = tuple(MEASURE_UNITS)
#: Default largest scale factor on a record (larger factors distort a record's character).
MAX_SCALE = 10.0
#: The methods a suite may ask for (``[model] method``; "auto": `multimass.sweeps.method_choice`).
METHODS = ("DOP853", "exponential", "auto")
#: Plausible PGA range of a record in its stated units (g): outside, the units are wrong.
_PGA_RANGE_G = (0.005, 3.0)
#: Records whose PGAs differ by more than this factor are refused as a unit mix.
_PGA_SPREAD = 100.0

_OPTIONAL = {"description", "model", "monte_carlo", "pulses", "records"}
_REQUIRED = {"name", "structure", "intensity"}


def _fail(where: str, key: str, value, fix: str) -> InputError:
    return InputError(f"{where}: `{key}` = {value!r:.80}: {fix}")


def _keys(where: str, table: str, data, allowed: set, required: set = frozenset()) -> None:
    if not isinstance(data, dict):
        raise InputError(f"{where}: `{table}` must be a table ([{table}]), not {data!r:.60}")
    unknown = sorted(set(data) - allowed - set(required))
    if unknown:
        raise InputError(
            f"{where}: unknown key `{table + '.' if table else ''}{unknown[0]}`; remove it or "
            f"correct its spelling (allowed: {', '.join(sorted(allowed | set(required)))})"
        )
    for key in sorted(required):
        if key not in data:
            raise InputError(f"{where}: missing key `{table + '.' if table else ''}{key}`")


def _values(where: str, key: str, value, *, positive: bool = False) -> np.ndarray:
    """A list of numbers, one number, or {start, stop, count} (inclusive, like the CLI)."""
    if isinstance(value, dict):
        _keys(where, key, value, {"spacing"}, {"start", "stop", "count"})
        start = v.number(f"{key}.start", value["start"])
        stop = v.number(f"{key}.stop", value["stop"])
        count = v.integer(f"{key}.count", value["count"], low=1, what="how many values")
        spacing = value.get("spacing", "linear")
        if spacing == "log":
            if start <= 0 or stop <= 0:
                raise _fail(where, key, value, "log spacing needs start and stop > 0")
            out = np.geomspace(start, stop, count)
        elif spacing == "linear":
            out = np.linspace(start, stop, count)
        else:
            raise _fail(where, f"{key}.spacing", spacing, "use 'linear' or 'log'")
    elif isinstance(value, list):
        if not value:
            raise _fail(where, key, value, "give at least one value")
        out = np.array([v.number(f"{key}[{i}]", x) for i, x in enumerate(value)])
    else:
        out = np.array([v.number(key, value)])
    if positive and np.any(out <= 0):
        raise _fail(where, key, value, "every value must be > 0")
    if out.size > 1 and np.any(np.diff(out) <= 0):
        raise _fail(where, key, value, "give increasing values")
    return out


# --------------------------------------------------------------------------- distributions
@dataclass(frozen=True)
class Distribution:
    """A distribution of one restitution parameter, drawn once per run.

    Parameters
    ----------
    kind : {"uniform", "normal", "fixed"}
    a, b : float
        uniform: low, high; normal: mean, std (truncated to `low`..`high`); fixed: value.
    low, high : float
        Bounds of a drawn value (the restitution's range, [0, 1]).
    """

    kind: str
    a: float
    b: float = 0.0
    low: float = 0.0
    high: float = 1.0

    def draw(self, rng: np.random.Generator) -> float:
        """One value from `rng` (a normal draw is redrawn until it lies in [low, high])."""
        if self.kind == "fixed":
            return self.a
        if self.kind == "uniform":
            return float(rng.uniform(self.a, self.b))
        for _ in range(1000):
            x = float(rng.normal(self.a, self.b))
            if self.low <= x <= self.high:
                return x
        return float(np.clip(self.a, self.low, self.high))

    @classmethod
    def parse(
        cls, where: str, key: str, data, low: float = 0.0, high: float = 1.0, what: str = ""
    ) -> Distribution:
        """A value, or {distribution = "uniform", low, high} / {"normal", mean, std},
        within [`low`, `high`] (a normal draw is truncated there)."""
        about = what or f"a value in [{low:g}, {high:g}]"
        if not isinstance(data, dict):
            return cls("fixed", v.number(key, data, low=low, high=high, what=about), 0.0, low, high)
        kind = data.get("distribution")
        if kind == "uniform":
            _keys(where, key, data, set(), {"distribution", "low", "high"})
            lo = v.number(f"{key}.low", data["low"], low=low, high=high, what=about)
            hi = v.number(f"{key}.high", data["high"], low=low, high=high, what=about)
            if hi <= lo:
                raise _fail(where, f"{key}.high", hi, f"must exceed low = {lo:g}")
            return cls("uniform", lo, hi, low, high)
        if kind == "normal":
            _keys(where, key, data, set(), {"distribution", "mean", "std"})
            mean = v.number(f"{key}.mean", data["mean"], low=low, high=high, what=about)
            std = v.number(f"{key}.std", data["std"], low=0.0, low_open=True, high=(high - low) / 2)
            return cls("normal", mean, std, low, high)
        raise _fail(
            where,
            f"{key}.distribution",
            kind,
            f'use "uniform" (low, high) or "normal" (mean, std, truncated to [{low:g}, {high:g}])',
        )

    def describe(self) -> dict:
        names = {"uniform": ("low", "high"), "normal": ("mean", "std"), "fixed": ("value", "")}
        x, y = names[self.kind]
        return {"distribution": self.kind, x: self.a} | ({y: self.b} if y else {})


# --------------------------------------------------------------------------- pulses
@dataclass(frozen=True)
class PulseSet:
    """M&P pulses of a suite, starting at t = 0.

    Every combination of the listed ω_p/p, γ and ν values is one motion; a γ or ν given
    as a `Distribution` is drawn anew for every run (from the run's seed), which spreads
    the pulse shapes a suite covers (the record-to-record variability of near-fault
    pulses; M&P 2003 fitted γ ≈ 1.5–3 and ν over the whole circle).
    """

    omega_p_over_p: tuple[float, ...]
    gamma: tuple[float, ...] | Distribution = (2.0,)
    nu: tuple[float, ...] | Distribution = (0.0,)

    @property
    def drawn(self) -> bool:
        """True if γ or ν is drawn per run."""
        return isinstance(self.gamma, Distribution) or isinstance(self.nu, Distribution)

    def combinations(self) -> list[tuple[float, object, object]]:
        """(ω_p/p, γ, ν) of every motion; γ and ν a float or a `Distribution`."""
        gs = [self.gamma] if isinstance(self.gamma, Distribution) else list(self.gamma)
        ns = [self.nu] if isinstance(self.nu, Distribution) else list(self.nu)
        return [(w, g, n) for g in gs for n in ns for w in self.omega_p_over_p]

    def describe(self) -> dict:
        out = {}
        for key in ("gamma", "nu"):
            val = getattr(self, key)
            out[key] = val.describe() if isinstance(val, Distribution) else list(val)
        return {"omega_p_over_p": list(self.omega_p_over_p)} | out


# --------------------------------------------------------------------------- the suite
@dataclass(frozen=True, eq=False)
class Suite:
    """What a suite runs (see the module docstring for the TOML form).

    Attributes
    ----------
    name : str
    structure : Structure
    records : tuple of Record
        Unscaled records.
    pulses : PulseSet or None
    measure : str
        One of `MEASURES`.
    levels : ndarray
        Intensity levels in SI units (m/s², m/s, m; 1 for scale and a_p/(g tan α)).
    period : float or None
        T (s) of ``measure = "sa"``.
    damping : float
        ζ of Sa (default 0.05).
    draws : int
        Runs per motion and level.
    seed : int
    impact, restitution : str
    k : Distribution or None
        η_M's k drawn per run (blocks, restitution "modified").
    restitution_value : Distribution or None
        A fixed restitution value drawn per run.
    t_free : float
        Free response after the motion (s).
    max_scale : float
    sa_periods : tuple of float
        Periods (s) of the Sa columns written beside the other IMs.
    options : dict
        Other keyword arguments of `multimass.simulate_outcome`.
    """

    name: str
    structure: Structure
    records: tuple = ()
    pulses: PulseSet | None = None
    measure: str = "pga"
    levels: np.ndarray = field(default_factory=lambda: np.array([1.0]))
    period: float | None = None
    damping: float = 0.05
    draws: int = 1
    seed: int = 0
    impact: str = "CIM"
    restitution: str | None = None
    k: Distribution | None = None
    restitution_value: Distribution | None = None
    t_free: float = 5.0
    max_scale: float = MAX_SCALE
    sa_periods: tuple = ()
    options: dict = field(default_factory=dict)
    source: str = "Suite"

    def __post_init__(self):
        w = self.source
        if not self.records and self.pulses is None:
            raise InputError(
                f"{w}: the suite has no motion: add [[records]] (files) or [pulses] "
                "(M&P pulses); an empty record list runs nothing"
            )
        if self.measure not in MEASURES:
            raise _fail(w, "intensity.measure", self.measure, f"use one of {', '.join(MEASURES)}")
        if self.measure == "amp_over_g_tan_alpha" and self.records:
            raise _fail(
                w,
                "intensity.measure",
                self.measure,
                "a_p/(g tan α) scales pulses only; with records use pga, pgv, sa or scale",
            )
        if (
            self.pulses is not None
            and self.pulses.drawn
            and self.measure not in ("amp_over_g_tan_alpha", "pga", "scale")
        ):
            raise _fail(
                w,
                "intensity.measure",
                self.measure,
                "pulses whose γ or ν is drawn per run are scaled by their peak acceleration: "
                "use amp_over_g_tan_alpha or pga (or give γ and ν as values)",
            )
        if self.measure == "sa" and self.period is None:
            raise InputError(f"{w}: `intensity.measure` = 'sa' needs `intensity.period_s`")
        if len(self.levels) == 0:
            raise InputError(f"{w}: `intensity.levels` is empty; give at least one level")
        if np.any(~np.isfinite(self.levels)) or np.any(np.asarray(self.levels) <= 0):
            raise _fail(w, "intensity.levels", list(self.levels), "every level must be > 0")
        v.integer("monte_carlo.draws", self.draws, low=1, what="runs per motion and level")
        if self.k is not None and self.restitution != "modified":
            raise InputError(
                f"{w}: `monte_carlo.k` draws η_M's k, which only restitution = 'modified' uses "
                f"(got restitution = {self.restitution!r})"
            )
        if self.k is not None and self.restitution_value is not None:
            raise InputError(f"{w}: give `monte_carlo.k` or `monte_carlo.restitution`, not both")

    # ------------------------------------------------------------------ runs
    @property
    def n_motions(self) -> int:
        return len(self.records) + (len(self.pulses.combinations()) if self.pulses else 0)

    @property
    def n_runs(self) -> int:
        return self.n_motions * len(self.levels) * self.draws

    def describe(self) -> dict:
        """JSON-ready description (also the fingerprint of a stored suite)."""
        return {
            "name": self.name,
            "structure": self.structure.name,
            "records": [
                {"name": r.name, "source": r.source, "units": r.units, "n": int(r.time.size)}
                for r in self.records
            ],
            "pulses": None if self.pulses is None else self.pulses.describe(),
            "measure": self.measure,
            "levels": [float(x) for x in self.levels],
            "period_s": self.period,
            "damping": self.damping,
            "draws": int(self.draws),
            "seed": int(self.seed),
            "impact": self.impact,
            "restitution": self.restitution,
            "k": None if self.k is None else self.k.describe(),
            "restitution_value": None
            if self.restitution_value is None
            else self.restitution_value.describe(),
            "t_free_s": self.t_free,
            "max_scale": self.max_scale,
            "sa_periods": list(self.sa_periods),
            "options": {k: self.options[k] for k in sorted(self.options)},
        }

    # ------------------------------------------------------------------ TOML
    @classmethod
    def from_toml(cls, path) -> Suite:
        """Read and check a suite file (relative paths are taken from its folder)."""
        from ..inputs.textfile import read_text

        p = Path(path)
        text = read_text(p, what="a suite TOML file", argument="SUITE", suffixes=(".toml",))
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise InputError(f"{p}: not valid TOML ({exc}); fix the syntax") from None
        return cls.from_mapping(data, str(p), p.parent)

    @classmethod
    def from_mapping(cls, data: dict, source: str = "suite", folder=".") -> Suite:
        """A suite from a parsed TOML mapping; `source` names it in errors."""
        w, folder = source, Path(folder)
        _keys(w, "", data, _OPTIONAL, _REQUIRED)
        name = data["name"]
        if not isinstance(name, str) or not name.strip():
            raise _fail(w, "name", name, "give the suite a name")
        st = _structure(w, data["structure"], folder)
        model = data.get("model", {})
        _keys(
            w,
            "model",
            model,
            {"impact", "restitution", "t_free_s", "backend", "max_scale", "method"},
        )
        kind = "block" if st.n == 0 else "column"
        impact = model.get("impact", "CIM" if kind == "block" else "DD5")
        restitution = model.get("restitution")
        if restitution is not None and not isinstance(restitution, (str, int, float)):
            raise _fail(w, "model.restitution", restitution, "give a name or a value")
        t_free = v.positive("model.t_free_s", model.get("t_free_s", 5.0), "free response, s")
        max_scale = v.positive("model.max_scale", model.get("max_scale", MAX_SCALE), "a factor")
        options = {}
        if "backend" in model:
            options["backend"] = v.choice("model.backend", model["backend"], ("compiled", "scipy"))
        if "method" in model:
            options["method"] = v.choice("model.method", model["method"], METHODS)
        mc = data.get("monte_carlo", {})
        _keys(w, "monte_carlo", mc, {"draws", "seed", "k", "restitution"})
        draws = v.integer("monte_carlo.draws", mc.get("draws", 1), low=1, what="runs per level")
        seed = v.integer("monte_carlo.seed", mc.get("seed", 0), low=0, what="a seed")
        k = Distribution.parse(w, "monte_carlo.k", mc["k"]) if "k" in mc else None
        rv = (
            Distribution.parse(w, "monte_carlo.restitution", mc["restitution"])
            if "restitution" in mc
            else None
        )
        if k is not None and restitution is None:
            restitution = "modified"
        records = tuple(_records(w, data.get("records", []), folder))
        pulses = _pulses(w, data["pulses"]) if "pulses" in data else None
        measure, levels, period, damping, sa_periods = _intensity(w, data["intensity"])
        return cls(
            name=name.strip(),
            structure=st,
            records=records,
            pulses=pulses,
            measure=measure,
            levels=levels,
            period=period,
            damping=damping,
            draws=draws,
            seed=seed,
            impact=impact,
            restitution=restitution,
            k=k,
            restitution_value=rv,
            t_free=t_free,
            max_scale=max_scale,
            sa_periods=sa_periods,
            options=options,
            source=w,
        )


def _structure(w: str, data, folder: Path) -> Structure:
    from .. import specimens

    _keys(w, "structure", data, set(), {"specimen"})
    spec = data["specimen"]
    if not isinstance(spec, str) or not spec:
        raise _fail(w, "structure.specimen", spec, "give a bundled name or a TOML path")
    if spec not in specimens.available():
        p = Path(spec).expanduser()
        spec = str(p if p.is_absolute() else folder / p)
    try:
        return from_specimen(spec)
    except InputError as exc:
        raise InputError(f"{w}: [structure] {exc}") from None


def _records(w: str, items, folder: Path) -> list[Record]:
    if not isinstance(items, list):
        raise _fail(w, "records", items, "write each record as a [[records]] table")
    out = []
    for i, item in enumerate(items):
        where = f"{w}: records[{i}]"
        _keys(where, "records", item, {"units", "name"}, {"path"})
        raw = item["path"]
        if not isinstance(raw, str) or not raw:
            raise _fail(where, "path", raw, "give the record file's path")
        p = Path(raw).expanduser()
        p = p if p.is_absolute() else folder / p
        if not p.is_file():
            raise _fail(where, "path", raw, f"no such file ({p}); paths are relative to the suite")
        try:
            rec = read_record(p, units=item.get("units"), name=item.get("name", p.stem))
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None
        out.append(rec)
    names = [r.name for r in out]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise InputError(f"{w}: two records are named {dupes[0]!r}; give each a distinct `name`")
    check_record_units(w, out)
    return out


def check_record_units(w: str, records) -> None:
    """Refuse records whose PGA is implausible in their units, or that mix units.

    Raises
    ------
    InputError
        Naming the record, its PGA in its stated units and the fix.
    """
    pgas = {}
    for r in records:
        pga_g = float(np.max(np.abs(r.accel))) / G
        lo, hi = _PGA_RANGE_G
        if not lo <= pga_g <= hi:
            raise InputError(
                f"{w}: record {r.name!r} ({r.source}) has PGA {pga_g:.4g} g read in "
                f"units {r.units!r}, outside {lo:g}–{hi:g} g: its `units` are wrong "
                f"(m/s² read as g gives ~9.81× too much; cm/s² read as m/s² 100×); "
                "set `units` of this record to the file's"
            )
        pgas[r.name] = pga_g
    if len(pgas) > 1:
        big, small = max(pgas, key=pgas.get), min(pgas, key=pgas.get)
        if pgas[big] / pgas[small] > _PGA_SPREAD:
            raise InputError(
                f"{w}: records in different units? {big!r} has PGA {pgas[big]:.3g} g and "
                f"{small!r} {pgas[small]:.3g} g ({pgas[big] / pgas[small]:.0f}×); give each "
                "[[records]] table the `units` of its own file"
            )


def _pulses(w: str, data) -> PulseSet:
    _keys(w, "pulses", data, {"gamma", "nu_rad", "kind"}, {"omega_p_over_p"})
    if data.get("kind", "mp") != "mp":
        raise _fail(w, "pulses.kind", data["kind"], 'only "mp" (Mavroeidis & Papageorgiou)')
    omega = _values(w, "pulses.omega_p_over_p", data["omega_p_over_p"], positive=True)

    def shape_values(key, default, low, high, what):
        value = data.get(key, default)
        if isinstance(value, dict) and "distribution" in value:
            return Distribution.parse(w, f"pulses.{key}", value, low, high, what)
        vals = _values(w, f"pulses.{key}", value)
        return tuple(map(float, vals))

    gamma = shape_values("gamma", 2.0, 1.0 + 1e-9, MP_MAX_GAMMA, "γ of the M&P pulse, > 1")
    nu = shape_values("nu_rad", 0.0, -2 * math.pi, 2 * math.pi, "the phase ν in rad")
    for g in gamma if isinstance(gamma, tuple) else ():
        for n in nu if isinstance(nu, tuple) else (0.0,):
            try:
                MPShape(gamma=g, nu=n)
            except InputError as exc:
                raise InputError(f"{w}: [pulses] {exc}") from None
    if isinstance(nu, tuple):
        for n in nu:
            MPShape(nu=n)
    return PulseSet(tuple(map(float, omega)), gamma, nu)


def _intensity(w: str, data):
    _keys(
        w, "intensity", data, {"unit", "period_s", "damping", "sa_periods_s"}, {"measure", "levels"}
    )
    measure = data["measure"]
    if measure not in MEASURES:
        raise _fail(w, "intensity.measure", measure, f"use one of {', '.join(MEASURES)}")
    units = MEASURE_UNITS[measure]
    unit = data.get("unit", units[0])
    if unit not in units:
        raise _fail(w, "intensity.unit", unit, f"{measure} levels are in {' or '.join(units)}")
    levels = _values(w, "intensity.levels", data["levels"], positive=True)
    if unit == "g":
        levels = levels * G
    period = None
    if measure == "sa" or "period_s" in data:
        if "period_s" not in data:
            raise InputError(f"{w}: `intensity.measure` = 'sa' needs `intensity.period_s` (s)")
        period = v.positive("intensity.period_s", data["period_s"], "the period of Sa, s")
    damping = v.number(
        "intensity.damping", data.get("damping", 0.05), low=0.0, high=1.0, low_open=True
    )
    periods = set()  # the periods of the Sa columns written beside the other IMs
    if data.get("sa_periods_s"):
        listed = _values(w, "intensity.sa_periods_s", data["sa_periods_s"], positive=True)
        periods = set(map(float, listed))
    if period is not None:
        periods.add(period)
    return measure, levels, period, damping, tuple(sorted(periods))
