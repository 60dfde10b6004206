"""Synthetic test traces with a known truth.

`synthetic_trace` simulates a test with `multimass.simulate` and records it as a
data-acquisition system would, so that every identification step can be tested by
recovering the truth it was given:

1. restitution drawn per impact: before the run, two tables of coefficients are
   drawn from N(r̄_er, σ) and N(r̄_el, σ) (the specimen's corner means and σ_r of
   paper 001 Table 1 unless given), truncated to (0, 1] by redrawing; the run's
   i-th draw takes the table of the corner it is for
   (`multimass.impact_models.DrawnRestitution`); the events say which value each
   impact took;
2. the response is computed on a uniform grid at ``oversample × fs`` (8 kHz by
   default, above 2.5 times the highest mode of the bundled columns, 638 Hz), with
   the structure held still at its initial state before the release; a cell in
   which the response jumps (an impact, the release) holds its mean, so a jump
   keeps its place inside the cell. Against a grid four times finer, the recorded
   accelerations of S1–S3 (CIM and DD2, 0.11 rad release, 10 s) differ by at most
   0.14 % of their peak and θ by 3e-7 of its (measured for this module);
3. an anti-alias filter and sampling at `fs` (`multimass.identify.sampling`: a
   linear-phase FIR, flat to 0.4 `fs`, ≥ 80 dB from `fs`/2, applied zero-phase)
   on a clock whose t = 0 is `t_offset` before the simulation's;
4. a constant bias per channel and white Gaussian noise (a fraction of each
   channel's peak), seeded.

The trace carries the specimen's name (``# specimen: NAME``) and nothing else of
the truth; `SyntheticTrace.write` puts the truth in a sidecar JSON file next to it
(``NAME.truth.json``, `truth_path`, `read_truth`).

>>> from multimass import FreeRelease
>>> syn = synthetic_trace("S1", FreeRelease(theta0=0.11), "DD2", 2.0, seed=1)
>>> syn.trace.specimen, syn.trace.names
('S1', ('theta', 'a_A1', 'a_A2', 'a_A3', 'a_A4'))
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from multimass.impact_models import CornerRestitution, DrawnRestitution

from ..errors import InputError
from ..inputs.textfile import as_path, read_text
from ..inputs.traces import Trace, format_trace, parse_trace
from ..model.structure import Structure, from_specimen
from ..response import Response
from ..result import json_ready
from . import _synthetic_run as simulation
from . import _synthetic_setup as setup
from ._synthetic_truth import truth as make_truth
from .sampling import anti_alias_fir, fir_figures, resample

__all__ = ["SyntheticTrace", "synthetic_trace", "read_truth", "truth_path", "TRUTH_FORMAT"]

#: The ``format`` key of every truth file.
TRUTH_FORMAT = "multimass synthetic-trace truth"
_TRUTH_VERSION = 1
_DIGITS = 10  # significant digits written (the Trace holds exactly what the file holds)
_UNITS = {"theta": "rad", "ag": "g"}  # written units; accelerations in g


@dataclass(frozen=True, eq=False)
class SyntheticTrace:
    """A synthetic trace and the truth it was made from (`synthetic_trace`).

    Attributes
    ----------
    trace : multimass.inputs.traces.Trace
        What a test would record: filtered, sampled, biased and noisy, rounded to
        the digits written; ``trace.specimen`` names the specimen.
    truth : dict
        JSON-ready truth (SI units, rad; times ``t`` on the trace's clock and
        ``t_model`` on the simulation's): ``specimen``, ``impact``, ``seed``,
        ``excitation``, ``t_offset``, ``impacts`` (``t``, ``t_model``, ``corner``
        "right"/"left", ``r``, ``theta_before``, ``theta_after``), ``r_mean_right``,
        ``r_mean_left``, ``sigma_r``, ``transitions``, ``peaks``, ``noise``, ``bias``,
        ``restitution``, ``damping`` (``zeta_1``, ``zeta_2`` of a column; None for
        a block), ``sampling`` (the anti-alias filter's measured figures),
        ``simulation``.
    clean : multimass.inputs.traces.Trace
        The same samples before bias and noise (not rounded).
    response : multimass.Response
        The simulation, sampled at the high rate.
    """

    trace: Trace
    truth: dict
    clean: Trace
    response: Response

    def write(self, path) -> tuple[Path, Path]:
        """Write the trace CSV to `path` and its truth to `truth_path(path)`.

        Parameters
        ----------
        path : str or Path
            The trace file (``.csv``); missing folders are created, existing files
            replaced.

        Returns
        -------
        (Path, Path)
            The trace file and the truth file.
        """
        out = as_path(path, what="the trace CSV file to write")
        if out.suffix.lower() != ".csv":
            raise InputError(f"`path` = {str(out)!r}: give a file name ending in .csv")
        out.parent.mkdir(parents=True, exist_ok=True)
        text = format_trace(self.trace, digits=_DIGITS)
        out.write_text(text, encoding="utf-8")
        side = truth_path(out)
        truth = {
            **self.truth,
            "trace_file": out.name,
            "trace_sha256": hashlib.sha256(text.encode("utf-8")).hexdigest(),
        }
        side.write_text(json.dumps(json_ready(truth), indent=1) + "\n", encoding="utf-8")
        return out, side


def truth_path(trace_path) -> Path:
    """The truth file of a trace file: ``name.csv`` → ``name.truth.json`` beside it."""
    p = as_path(trace_path, what="a trace CSV file")
    name = p.name[: -len(p.suffix)] if p.suffix.lower() == ".csv" else p.name
    return p.with_name(f"{name}.truth.json")


def read_truth(path) -> dict:
    """The truth of a synthetic trace, from the trace file or the truth file itself.

    Parameters
    ----------
    path : str or Path
        ``name.csv`` (its ``name.truth.json`` is read) or ``name.truth.json``.

    Returns
    -------
    dict
        As `SyntheticTrace.truth`, with ``trace_file`` and ``trace_sha256``.

    Raises
    ------
    InputError
        A missing or unreadable file, or one that is not a truth file.
    """
    p = as_path(path, what="a synthetic trace's truth file (.truth.json) or its trace (.csv)")
    side = p if p.name.lower().endswith(".truth.json") else truth_path(p)
    text = read_text(side, what="a synthetic trace's truth file (name.truth.json)")
    try:
        data = json.loads(text)
    except json.JSONDecodeError as err:
        raise InputError(f"{side}: not JSON ({err.msg}, line {err.lineno})") from None
    if not isinstance(data, dict) or data.get("format") != TRUTH_FORMAT:
        raise InputError(
            f"{side}: not a truth file of multimass.identify.synthetic_trace (no "
            f"`format` = {TRUTH_FORMAT!r}); give the .truth.json written with the trace"
        )
    return data


# ---------------------------------------------------------------------------- the simulator
def synthetic_trace(
    structure,
    excitation,
    impact="DD2",
    t_end: float = 10.0,
    *,
    seed: int,
    fs: float = 200.0,
    noise: float = 0.02,
    bias=0.005,
    t_offset: float = 0.012,
    sensors=None,
    restitution_means=None,
    restitution_spread=None,
    C_p: float | None = None,
    damping=None,
    passband: float = 0.4,
    oversample: int = 40,
    **options,
) -> SyntheticTrace:
    """Simulate a test and record it as a trace, keeping the truth apart.

    Parameters
    ----------
    structure : Structure, specimen or str
        What is tested, e.g. ``"S1"``.
    excitation : Excitation
        `FreeRelease` for a free-vibration test; any other excitation is table
        motion, recorded as the ``ag`` channel.
    impact : str or ImpactModel, optional
        "CIM", "DD1" … "DD5", "DD" (paper 001, Table 2; C_p from the table) or a
        `Classical` / `DiracDelta` object; its restitution is replaced by the drawn
        one. "LCP" draws no restitution and is refused.
    t_end : float, optional
        End of the simulated test (s); the trace covers the simulation's times
        ``-t_offset`` (or 0) to `t_end`.
    seed : int
        Seed (≥ 0) of every random draw: restitution, bias and noise. Same seed,
        same trace.
    fs : float, optional
        Sampling rate of the trace (Hz; default 200).
    noise : float, optional
        Standard deviation of the white Gaussian sensor noise, as a fraction of each
        channel's peak ``|value|`` (in [0, 1]; default 0.02).
    bias : float or mapping, optional
        A float in [0, 1]: each channel's constant bias is drawn uniformly in
        ± `bias` × its peak (default 0.005). A mapping: channel name (``"theta"``,
        ``"a_A2"``, ``"ag"``) → bias in SI units (rad, m/s²); channels not named
        get none.
    t_offset : float, optional
        Trace time of the simulation's t = 0 (s; as in `multimass.compare_trace`):
        > 0 records the structure held still for that long before the release;
        < 0 starts recording after it. Default 0.012 s (2.4 samples at 200 Hz).
    sensors : sequence of str or int, optional
        Accelerometers to record: the specimen's sensor names (``"A2"``, column
        ``a_A2``) or 1-based nodes (``3``, column ``a3``). Default: every named
        sensor of the specimen, else every node; none for a rigid block.
    restitution_means : (float, float), optional
        Corner means (r̄_er, r̄_el) in (0, 1]; default the specimen's.
    restitution_spread : float, optional
        Standard deviation of the drawn coefficients (in [0, 0.5]); default the
        specimen's σ_r. 0 gives the means at every impact.
    C_p : float, optional
        Replaces the Table 2 C_p of a Dirac-delta model named by `impact`.
    damping : (float, float), optional
        The Rayleigh damping ratios (ζ1, ζ2) of the full-contact modes 1 and 2
        (fractions of critical, in [0, 1)) replacing the column specimen's; the
        truth's ``damping`` holds the ratios simulated either way.
    passband : float, optional
        End of the anti-alias filter's flat passband as a fraction of `fs`
        (default 0.4; the stopband starts at `fs` / 2).
    oversample : int, optional
        Rate of the simulated samples as a multiple of `fs` (default 40); 2.5 times the
        structure's highest full-contact frequency must stay below it.
    **options
        Other options of `multimass.simulate` (``rtol``, ``method``,
        ``thetadot_min``, ``backend``, ...). By default the compiled backend runs
        when it knows the impact model and the excitation, else SciPy's.

    Returns
    -------
    SyntheticTrace
        ``trace``, ``truth``, ``clean`` and ``response``; `SyntheticTrace.write`
        writes the trace and its truth file.

    Raises
    ------
    InputError
        For an invalid argument (named in the message), a run that overturns, or
        an impact model without restitution.
    SolverError
        If the simulation fails.
    """
    st = structure if isinstance(structure, Structure) else from_specimen(structure)
    st = setup.with_damping(st, damping)
    cfg = setup.settings(
        st, excitation, t_end, seed, fs, noise, bias, t_offset, sensors, passband, oversample
    )
    simulation.check_options(options)
    streams = np.random.SeedSequence(cfg.seed).spawn(3)  # restitution, bias, noise
    means, spread = setup.restitution_law(st, restitution_means, restitution_spread)
    taps = anti_alias_fir(cfg.fs_in, cfg.fs, passband=cfg.passband)
    grid = setup.grids(cfg, (taps.size - 1) // 2)
    placeholder = DrawnRestitution((1.0,), (1.0,), CornerRestitution(*means))
    model = simulation.model_of(st, impact, C_p, placeholder)  # checked before the run
    response, model, tables = simulation.run(
        st, excitation, model, means, spread, streams[0], grid, cfg, options
    )
    high = _high_rate(response, cfg.columns, grid)
    clean = {
        name: resample(values, cfg.fs_in, grid.t_high[0], grid.t_model, taps)
        for name, values in high.items()
    }
    peak = {name: float(np.max(np.abs(x))) for name, x in clean.items()}
    biases = _biases(cfg, peak, np.random.default_rng(streams[1]))
    rng = np.random.default_rng(streams[2])
    measured = {
        name: x + biases[name] + rng.normal(0.0, cfg.noise * peak[name], x.size)
        for name, x in clean.items()
    }
    truth = {
        "format": TRUTH_FORMAT,
        "version": _TRUTH_VERSION,
        **make_truth(
            st,
            excitation,
            response,
            model,
            tables,
            cfg,
            grid,
            {"means": means, "spread": spread},
            {"peak": peak, "bias": biases},
            fir_figures(taps, cfg.fs_in, cfg.fs, passband=cfg.passband),
        ),
    }
    return SyntheticTrace(
        _as_trace(grid.t_trace, measured, st, rounded=True),
        truth,
        _as_trace(grid.t_trace, clean, st, rounded=False),
        response,
    )


def _high_rate(response, columns: dict, grid) -> dict:
    """Each channel on the uniform high-rate grid, held still before t = 0.

    A sample is the response at its time (the midpoint rule of the filter's
    convolution integral), except in a cell where the response jumps (an event, the
    release): there the cell's mean, so that a jump keeps its position inside the
    cell instead of moving to the next grid point.
    """
    df = response.series
    t = df["t"].to_numpy()
    after = grid.t_high >= 0.0
    x = grid.t_high[after]
    i = np.clip(np.searchsorted(t, x, side="right"), 1, t.size - 1)
    t0, t1 = t[i - 1], t[i]
    span = t1 - t0
    w = np.where(span > 0.0, (x - t0) / np.where(span > 0.0, span, 1.0), 1.0)
    same = np.flatnonzero(np.diff(t) == 0.0)  # a jump: two rows at one time
    h = grid.t_high[1] - grid.t_high[0]
    out = {}
    for name, column in columns.items():
        y = df[column].to_numpy()
        held = float(y[0]) if column == "theta" else 0.0  # held still: no acceleration
        values = np.full(grid.t_high.size, held)
        values[after] = y[i - 1] + w * (y[i] - y[i - 1])
        t_jump = np.concatenate([[0.0], t[same]])
        size = np.concatenate([[y[t == t[0]][-1] - held], y[same + 1] - y[same]])
        cell = np.clip(np.rint((t_jump - grid.t_high[0]) / h).astype(int), 0, values.size - 1)
        before = (t_jump - (grid.t_high[cell] - 0.5 * h)) / h  # part of the cell before it
        took_after = t_jump <= grid.t_high[cell]  # the sample took the value after the jump
        np.add.at(values, cell, size * (1.0 - np.clip(before, 0.0, 1.0) - took_after))
        out[name] = values
    return out


def _biases(cfg, peak: dict, rng) -> dict:
    """Each channel's constant bias (SI): drawn in ± bias × peak, or as given."""
    if isinstance(cfg.bias, Mapping):
        return {name: float(cfg.bias.get(name, 0.0)) for name in peak}
    return {name: float(cfg.bias * p * rng.uniform(-1.0, 1.0)) for name, p in peak.items()}


def _as_trace(time, channels: dict, st, rounded: bool) -> Trace:
    """A Trace of the channels; `rounded`: exactly what its file holds (`format_trace`)."""
    trace = Trace(
        time=time,
        channels=channels,
        units={name: _UNITS.get(name, "g") for name in channels},
        source="synthetic" if rounded else "synthetic (clean)",
        g=st.g,
        specimen=st.name,
    )
    if not rounded:
        return trace
    return parse_trace(format_trace(trace, digits=_DIGITS), source="synthetic", g=st.g)
