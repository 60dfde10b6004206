"""Operational modes from a shake-table trace, against the model (issue 14, item 2).

Paper 001 (Section 4.2, Fig 5) identified the frequencies and "operational acceleration
profiles" of each specimen from the accelerations of free-vibration tests, half-cycle
by half-cycle, and compared them (MAC) with the compound shapes v_c = v_t + H v_r of
its uplifted modes. `operational_modes` does the same for a recorded trace and adds
the full-contact modes, compared with the full-contact shapes v_n:

1. the trace is cut into rocking half-cycles and full-contact stretches
   (`multimass.identify.segments.segment_trace`); the samples of each that belong to
   one linear phase are kept (`multimass.identify._modes_select`);
2. in each, the rigid-body part of the accelerations that rocking imposes (paper 001,
   Section 4.3's "step function") is removed as a polynomial in time per sensor —
   degree 2 in a half-cycle, 0 (the sensor's bias) in full contact — fitted together
   with the modes (`multimass.identify._modes_fit` states why a polynomial);
3. each mode's frequency, damping and complex amplitude per sensor are estimated two
   ways: ``method="fit"``, a least-squares fit of damped sinusoids with frequencies and
   damping common to all sensors (variable projection, started from the FFT peaks),
   or ``method="fft"``, the peaks of the zero-padded spectra (the paper's way), the
   damping from the half-power width corrected for the window;
4. the segments are combined per mode, each weighted by the mode's energy in it (its
   fitted part over the sensor noise, squared and summed: long, strongly excited
   segments count most); a mode counts in a segment when that energy is at least
   `MIN_ENERGY` noise variances (pure noise reaches 35 with the fit, 90 with the FFT);
   the spread is the weighted standard deviation over the segments;
5. the shapes (real: each segment's complex shape turned to its principal real
   direction, unit norm, the sign that correlates positively with the model's shape of
   the same mode, then averaged) are compared with `multimass.modal.analyse` at the
   sensors' nodes: MAC against the compound shapes for the rocking phase, against the
   full-contact shapes for full contact.

**Which method.** Measured for this module, against known answers:

- *damped sinusoids with known parameters* (4 sensors, 20.5 and 45.65 Hz, ζ = 1.33 and
  1.77 %, a parabola added, white noise of ~6 % of the first mode's amplitude, 40
  draws): the r.m.s. error of one segment's f1 is 0.84 / 0.22 / 0.12 / 0.06 % for
  segments of 0.1 / 0.2 / 0.3 / 0.6 s with the fit, 2.9 / 0.62 / 0.24 / 0.08 % with
  the FFT; ζ1 comes out 1.26 ± 0.93 / 1.28 ± 0.21 / 1.33 ± 0.14 / 1.32 ± 0.06 % (fit)
  against 19 ± 4 / 3.7 ± 1.8 / 1.9 ± 1.1 / 1.39 ± 0.19 % (FFT);
- *synthetic S1 traces* (`synthetic_trace`: 0.11 rad release, 10 s, 200 Hz, noise 2 % of
  each channel's peak; DD2 and CIM, seeds 1–3), against `multimass.modal.analyse`:
  uplifted f1 +0.09…+0.12 % (fit) and −0.12…+0.10 % (FFT), f2 −0.03…+0.09 % and
  −0.18…+0.08 %; one half-cycle's f1 errs by 0.13–0.21 % r.m.s. (fit) against
  0.49–0.52 % (FFT); ζ1 1.28–1.35 % (fit) against 1.32–2.21 % (FFT) for the model's
  1.33 %, ζ2 1.66–1.76 % against 1.41–1.72 % (1.77 %); MAC ≥ 0.9998 (fit), ≥ 0.998
  (FFT). Full contact (one stretch of ~5 s once the rocking has died down, 4.8–4.9 s
  after the release): f1 within 0.02 % and ζ1 0.49–0.51 % (model 0.50 %) both ways;
  f2, barely excited by then, −0.06…+0.27 % (fit, MAC ≥ 0.96) against −0.06…+0.77 %
  or not found (FFT).

No model is run: the operational modes depend on no C_p, restitution or damping
of the model, estimated or not; the model's modes they are compared with (and its
damping shown beside theirs) come from the specimen file (`OperationalModes.parameters`,
``parameters`` in the JSON, says which is which).

So the fit is the default (``method="fit"``): two to three times more precise per
half-cycle, and the only one whose damping can be used. (On a noiseless trace every
half-cycle's uplifted f1 sits +0.10 % (S1) and +0.25 % (S2) above the model's whatever
its amplitude: that offset is the simulated column's, not the method's.)

>>> from multimass import FreeRelease
>>> from multimass.identify import synthetic_trace
>>> syn = synthetic_trace("S1", FreeRelease(theta0=0.11), "DD2", 10.0, seed=1)
>>> res = operational_modes(syn.trace)
>>> res.rocking.freq_hz.round(1).tolist(), res.full_contact.freq_hz.round(2).tolist()
([20.5, 45.7], [7.47, 40.64])
>>> bool(res.rocking.mac.min() > 0.99)
True
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import validation as v
from ..errors import InputError
from ..modal import ModalAnalysis, analyse
from ..result import json_ready
from ..structure import Structure, from_specimen
from ..traces import Trace
from . import _modes_combine as combining
from . import _modes_fit as fitting
from . import _modes_select as select
from ._modes_combine import MIN_ENERGY
from ._trace_checks import check_ag
from .segments import THETA_MIN, Segments, require_trace, segment_trace

__all__ = ["OperationalModes", "IdentifiedModes", "operational_modes", "METHODS", "MIN_ENERGY"]

#: The estimators: "fit" (damped sinusoids, least squares; default) and "fft" (peaks).
METHODS = ("fit", "fft")
PHASES = ("rocking", "full_contact")


@dataclass(frozen=True, eq=False)
class IdentifiedModes:
    """The modes identified in one phase, against the model (one half of paper 001 Fig 5).

    Attributes
    ----------
    phase : str
        "rocking" (the half-cycles; compared with the uplifted compound shapes) or
        "full_contact".
    mode : ndarray of int, shape (K,)
        The model's mode number each identified mode is paired with, in the order
        of ascending identified frequency.
    freq_hz, damping : ndarray, shape (K,)
        Weighted means over the segments (Hz; fraction of critical).
    freq_spread_hz, damping_spread : ndarray, shape (K,)
        Weighted standard deviations over the segments.
    n_segments : ndarray of int, shape (K,)
        Segments in which the mode was found.
    shapes : ndarray, shape (S, K)
        Real operational shapes at the sensors (unit norm, sign: positive correlation
        with the model's shape of the same mode).
    complex_shapes : ndarray, complex, shape (S, K)
        The complex shapes, each segment's turned so that its principal direction is
        real, averaged alike (unit norm): their imaginary parts show how far the
        operational shapes are from real (classically damped) modes.
    model_freq_hz, model_damping : ndarray, shape (K,)
        The model's (`multimass.modal.analyse`) for the same modes.
    model_shapes : ndarray, shape (S, K)
        The model's compound (rocking) or full-contact shapes at the sensors' nodes,
        scaled to unit norm.
    mac : ndarray, shape (K,)
        MAC of each identified shape with the model's shape of its mode.
    mac_matrix : ndarray, shape (K, N)
        MAC of each identified shape with the model's modes 1..N.
    not_identified : dict
        Mode number → why it is not in the result (above the anti-alias passband, or
        found in no segment).
    segments : pandas.DataFrame
        One row per segment and mode asked: ``segment``, ``start``, ``stop``
        (sample range), ``t_start``, ``t_stop`` (s), ``half_cycle`` (index into
        `Segments.half_cycles`, −1 in full contact), ``mode``, ``freq_hz``,
        ``damping``, ``energy``, ``found``.
    skipped : dict
        Segments left out and why: ``too_short`` (count); for the rocking phase
        ``half_cycles_large`` (half-cycles above theta_min); for full contact
        ``still_rocking`` (stretches whose accelerations never settle into a free decay)
        and ``settled_s`` (per stretch used, the seconds cut from its start).
    """

    phase: str
    mode: np.ndarray
    freq_hz: np.ndarray
    damping: np.ndarray
    freq_spread_hz: np.ndarray
    damping_spread: np.ndarray
    n_segments: np.ndarray
    shapes: np.ndarray
    complex_shapes: np.ndarray
    model_freq_hz: np.ndarray
    model_damping: np.ndarray
    model_shapes: np.ndarray
    mac: np.ndarray
    mac_matrix: np.ndarray
    not_identified: dict
    segments: pd.DataFrame
    skipped: dict = field(default_factory=dict)

    def with_spread(self, k: int, what: str = "freq", scale: float = 1.0, digits: int = 3):
        """Mode ``k``'s frequency (``what="freq"``) or damping as text, ``x ± spread`` over
        its segments, or ``x`` alone where one segment leaves no spread to show."""
        value, spread = (
            (self.freq_hz[k], self.freq_spread_hz[k])
            if what == "freq"
            else (self.damping[k], self.damping_spread[k])
        )
        text = f"{scale * value:.{digits}f}"
        if self.n_segments[k] < 2:
            return text
        return f"{text} ± {scale * spread:.{digits}f}"

    def to_pandas(self) -> pd.DataFrame:
        """The Fig 5 table of this phase: one row per identified mode."""
        return pd.DataFrame(
            {
                "phase": self.phase,
                "mode": self.mode,
                "freq_hz": self.freq_hz,
                "model_freq_hz": self.model_freq_hz,
                "freq_error": self.freq_hz / self.model_freq_hz - 1.0,
                "freq_spread_hz": self.freq_spread_hz,
                "damping": self.damping,
                "model_damping": self.model_damping,
                "damping_spread": self.damping_spread,
                "mac": self.mac,
                "n_segments": self.n_segments,
            }
        )

    def to_dict(self) -> dict:
        """JSON-ready dict (frequencies in Hz, damping as fractions of critical):
        the arrays of the attributes as lists (``shapes``, ``model_shapes``: one list per
        mode of its ordinates at the sensors, bottom to top), ``freq_error`` (identified
        / model − 1), ``not_identified`` keyed by mode number, ``segments_used``."""
        return json_ready(
            {
                "mode": self.mode.tolist(),
                "freq_hz": self.freq_hz.tolist(),
                "mac": self.mac.tolist(),
                "damping": self.damping.tolist(),
                "freq_spread_hz": self.freq_spread_hz.tolist(),
                "damping_spread": self.damping_spread.tolist(),
                "n_segments": self.n_segments.tolist(),
                "model_freq_hz": self.model_freq_hz.tolist(),
                "model_damping": self.model_damping.tolist(),
                "freq_error": (self.freq_hz / self.model_freq_hz - 1.0).tolist(),
                "shapes": self.shapes.T.tolist(),
                "model_shapes": self.model_shapes.T.tolist(),
                "mac_matrix": self.mac_matrix.tolist(),
                "not_identified": {str(k): s for k, s in sorted(self.not_identified.items())},
                "segments_used": int(self.segments["segment"].nunique()),
                "skipped": self.skipped,
            }
        )


@dataclass(frozen=True, eq=False)
class OperationalModes:
    """Operational modes of a trace (`operational_modes`).

    Attributes
    ----------
    rocking, full_contact : IdentifiedModes or None
        None for a phase not asked.
    structure : Structure
    analysis : ModalAnalysis
        The model's modes with shapes at the sensors' nodes.
    sensors : tuple of str
        The trace columns used, bottom to top.
    nodes : tuple of int
        Their 1-based nodes.
    method : str
    fs : float
        Sampling rate (Hz).
    segments : Segments
    source : str
    warnings : tuple of str
    """

    rocking: IdentifiedModes | None
    full_contact: IdentifiedModes | None
    structure: Structure
    analysis: ModalAnalysis
    sensors: tuple
    nodes: tuple
    method: str
    fs: float
    segments: Segments
    source: str
    warnings: tuple = ()

    def parameters(self) -> dict:
        """Where each quantity of the result comes from (`_parameter_status`): the
        frequencies, damping ratios and shapes are *estimated* from the accelerations
        alone (no model is fitted: operational modes do not depend on C_p, the
        restitution or the model's damping, which are *not used*); the model's modes
        they are paired and compared with (MAC) come from the specimen's geometry,
        masses and stiffnesses (*fixed by the specimen file*), as do its damping ratios
        shown beside them."""
        from ._parameter_status import estimated_note, fixed, not_used, structure_fixed

        spec = self.structure.specimen
        unused = "operational modes are identified from the accelerations without a model run"
        return {
            "modes": estimated_note(
                "frequencies, damping ratios and shapes of each phase, with their spread "
                "over the segments"
            ),
            "sensor_bias": estimated_note("removed with each segment's polynomial"),
            "cp": not_used(unused, "C_p of the Dirac-delta impact force"),
            "restitution": not_used(unused, "coefficients of restitution"),
            "model_damping": fixed(
                [float(spec.zeta_1), float(spec.zeta_2)],
                "the model's Rayleigh damping ratios, shown beside the identified ones",
            ),
            "structure": fixed(
                structure_fixed(spec), "the model's modes the identified ones are compared with"
            ),
        }

    def phases(self) -> list[IdentifiedModes]:
        """The phases identified (rocking first)."""
        return [p for p in (self.rocking, self.full_contact) if p is not None]

    def to_pandas(self) -> pd.DataFrame:
        """Paper 001 Fig 5 as a table: identified against predicted frequency, damping
        and MAC, one row per mode and phase."""
        frames = [p.to_pandas() for p in self.phases()]
        return pd.concat(frames, ignore_index=True)

    def to_dict(self) -> dict:
        """JSON-ready dict: ``rocking`` and ``full_contact`` (None when not asked), each
        with ``freq_hz`` (ascending), ``mac``, ``damping``, ... (`IdentifiedModes.to_dict`)."""
        ref = getattr(self.structure.specimen, "reference", None)
        paper = {}
        for key in ("rocking_freq_hz", "full_contact_freq_hz"):
            if ref is not None and getattr(ref, key, None):
                paper[key] = list(getattr(ref, key))
        return json_ready(
            {
                "specimen": self.structure.name,
                "source": self.source,
                "method": self.method,
                "fs_hz": self.fs,
                "sensors": list(self.sensors),
                "nodes": list(self.nodes),
                "heights_m": self.analysis.heights.tolist(),
                "theta_min": self.segments.theta_min,
                "rocking": None if self.rocking is None else self.rocking.to_dict(),
                "full_contact": (
                    None if self.full_contact is None else self.full_contact.to_dict()
                ),
                "paper": paper,
                "parameters": self.parameters(),
                "warnings": list(self.warnings),
            }
        )

    def to_json(self, **kw) -> str:
        """`to_dict` as JSON text (keyword arguments go to `json.dumps`)."""
        return json.dumps(self.to_dict(), **kw)

    def shapes_csv(self, phase: str = "rocking") -> str:
        """The identified shapes of a phase in the format `multimass modal --measured`
        reads (`multimass.modal.measured`): ``node,mode_1,...``, one row per sensor node,
        then the ``freq_hz`` row."""
        pm = self._phase(phase)
        head = ",".join(["node", *(f"mode_{j}" for j in pm.mode)])
        rows = [head]
        for node, row in zip(self.nodes, pm.shapes):
            rows.append(",".join([str(node), *(f"{x:.8g}" for x in row)]))
        rows.append(",".join(["freq_hz", *(f"{f:.8g}" for f in pm.freq_hz)]))
        return "\n".join(rows) + "\n"

    def _phase(self, phase: str) -> IdentifiedModes:
        v.choice("phase", phase, PHASES)
        pm = getattr(self, phase)
        if pm is None:
            raise InputError(f"`phase` = {phase!r}: that phase was not identified (not asked)")
        return pm


def _structure(trace: Trace, structure) -> Structure:
    if structure is None:
        if not trace.specimen:
            raise InputError(
                f"{trace.source}: no specimen given and the trace has no `# specimen: NAME` "
                "line; give the specimen (e.g. --specimen S1)"
            )
        structure = trace.specimen
    st = structure if isinstance(structure, Structure) else from_specimen(structure)
    if st.n == 0:
        raise InputError(
            f"`structure` = {st.name!r}: a rigid block has no vibration modes; operational "
            "modes are for the multi-mass columns"
        )
    return st


def _args(trace, method, phases, modes, theta_min, min_periods):
    require_trace(trace)
    method = v.choice("method", method, METHODS)
    if isinstance(phases, str):
        phases = (phases,)
    if not isinstance(phases, (tuple, list)) or not phases:
        raise InputError(f"`phases` = {phases!r:.60}: give 'rocking', 'full_contact' or both")
    phases = tuple(v.choice("phases[...]", p, PHASES) for p in dict.fromkeys(phases))
    if modes is not None:
        if isinstance(modes, (str, bytes)) or not isinstance(modes, (list, tuple)) or not modes:
            raise InputError(f"`modes` = {modes!r:.60}: give mode numbers, e.g. [1, 2], or None")
        modes = sorted({v.integer("modes[...]", j, low=1, what="a mode number") for j in modes})
    theta_min = v.positive("theta_min", theta_min, "rad")
    min_periods = v.positive("min_periods", min_periods, "periods of the lowest mode asked")
    return method, phases, modes, theta_min, min_periods


def operational_modes(
    trace: Trace,
    structure=None,
    *,
    method: str = "fit",
    phases=PHASES,
    modes=None,
    sensors=None,
    theta_min: float = THETA_MIN,
    min_periods: float = 2.0,
    segments: Segments | None = None,
) -> OperationalModes:
    """Frequencies, damping and operational shapes of a trace, rocking and in full contact.

    Parameters
    ----------
    trace : Trace
        A test with a θ channel and accelerometers (``a_<sensor>``, ``a<k>``); a free
        vibration test, or table motion with an ``ag`` channel (subtracted from the
        sensors; the estimates then assume the table adds no vibration of its own).
    structure : Structure, specimen or str, optional
        The column tested; default the trace's ``# specimen:`` line.
    method : {"fit", "fft"}, optional
        Damped-sinusoid least squares (default: the more accurate, module docstring)
        or spectral peaks (paper 001's way).
    phases : str or sequence of str, optional
        "rocking" (half-cycles, compared with the uplifted compound shapes),
        "full_contact", or both (default). A phase asked but absent from the trace is
        an error, which names the other phase to ask for alone.
    modes : sequence of int, optional
        Model mode numbers to identify (default: every underdamped mode; those above
        0.4 × the sampling rate are listed as not identifiable, not fitted). A mode
        asked here that cannot be identified (above 0.4 × the sampling rate,
        overdamped, or not in the model) is an error.
    sensors : sequence of str or int, optional
        Sensor names of the specimen or 1-based nodes (default: every named sensor of
        the specimen, all of which the trace must have; for a specimen without named
        sensors, every acceleration column).
    theta_min : float, optional
        Half-cycles with a smaller peak (rad) are not used (paper 001, Section 4.3:
        0.01); it is `segment_trace`'s, unless `segments` are given.
    min_periods : float, optional
        Shortest half-cycle used (its samples away from the impacts), in periods of the
        lowest mode asked (default 2).
    segments : Segments, optional
        The trace's segments, if already found (`segment_trace`).

    Returns
    -------
    OperationalModes

    Raises
    ------
    InputError
        Naming the cause and the fix: no θ channel or specimen, a named sensor missing
        from the trace, a sampling rate too low to segment θ, an ``ag`` channel in an
        implausible unit, no half-cycle above `theta_min` (rocking asked), every
        half-cycle too short for the modes asked, no full-contact stretch with a free
        decay (full contact asked), every mode of a phase (or one asked by number)
        above the anti-alias passband.
    """
    method, phases, modes, theta_min, min_periods = _args(
        trace, method, phases, modes, theta_min, min_periods
    )
    st = _structure(trace, structure)
    seg = segments if segments is not None else segment_trace(trace, theta_min=theta_min)
    if not isinstance(seg, Segments) or seg.trace.time.size != trace.time.size:
        raise InputError("`segments`: give the Segments of this trace (segment_trace(trace))")
    names, nodes = select.sensor_channels(trace, st, sensors)
    check_ag(trace, st, seg)
    Y = np.column_stack([np.asarray(trace.channels[k], dtype=float) for k in names])
    warnings = []
    if trace.ag is not None:
        Y = Y - trace.ag[:, None]
        warnings.append(
            "table motion (`ag`) subtracted from the sensors; the free-decay fit assumes "
            "the table adds no vibration of its own within a segment"
        )
    analysis = analyse(st, tuple(nodes))
    # every phase's modes and samples are chosen (and checked) before any is fitted
    plans = {p: _plan(p, trace, seg, Y, analysis, modes, min_periods) for p in phases}
    out = {p: _phase(p, trace, seg, Y, analysis, plans[p], method) for p in phases}
    return OperationalModes(
        rocking=out.get("rocking"),
        full_contact=out.get("full_contact"),
        structure=st,
        analysis=analysis,
        sensors=tuple(names),
        nodes=tuple(nodes),
        method=method,
        fs=float(seg.fs),
        segments=seg,
        source=trace.source,
        warnings=tuple(warnings),
    )


def _plan(phase, trace, seg, Y, analysis, modes, min_periods):
    """(modes, freq_hz, damping, not identifiable, ranges, skipped) of a phase: the model's
    modes to identify and the samples to fit them in; InputError naming why there are none."""
    pm = analysis.rocking if phase == "rocking" else analysis.full_contact
    numbers, f_m, z_m, skip = select.model_modes(pm, modes, seg.fs)
    select.check_modes(trace.source, phase, numbers, skip, modes)
    if phase == "rocking":
        ranges, skipped = select.rocking_ranges(trace, seg, f_m, numbers.size, min_periods)
    else:
        ranges, skipped = select.contact_ranges(trace, seg, Y, f_m, z_m)
    return numbers, f_m, z_m, skip, ranges, skipped


def _phase(phase, trace, seg, Y, analysis, plan, method) -> IdentifiedModes:
    numbers, f_m, z_m, skip, ranges, skipped = plan
    fits, table = combining.estimate(
        trace.time, Y, ranges, numbers, f_m, z_m, method, fitting.DEGREE[phase], seg.fs
    )
    model = analysis.compound_shapes() if phase == "rocking" else analysis.full_contact_shapes()
    fields, missing = combining.combine(numbers, f_m, z_m, fits, table, model)
    return IdentifiedModes(
        phase=phase,
        not_identified={**skip, **missing},
        segments=table,
        skipped=skipped,
        **fields,
    )
