"""Ground excitations: callables ü_g(t) in m/s² with a duration and breakpoints.

Every excitation is a frozen, picklable dataclass (no lambdas stored), so sweeps can
send it to worker processes. The common contract (`Excitation`):

* ``acceleration(t)`` (also ``exc(t)``): ü_g at a float time (returns a float) or at an
  array of times (returns an array), in m/s²; zero before t = 0 and after `duration`;
* ``duration``: ü_g ≡ 0 after it (0.0 for a free release);
* ``breakpoints``: times in [0, duration] where ü_g or one of its low derivatives jumps
  (the start and the end of a pulse), so an integrator can stop and restart there;
* ``describe()``: a JSON-ready dict (``kind`` and the parameters in SI units).

Pulses take keyword arguments only, with the same names everywhere —
``SineWave(amplitude=0.4 * G, omega=15.0)``, ``CosinePulse(amplitude=..., omega=...)``,
``Ricker(amplitude=..., omega=...)`` — so an amplitude and a frequency can never be
swapped silently (both are plain numbers in SI units: m/s² and rad/s). The near-fault
pulse `MPPulse` keeps the symbols of its paper (``amplitude`` in m/s, ``fp`` in Hz,
``gamma``, ``nu``, ``t0``); `MPShape` builds it from a peak acceleration and ω_p like
the others. `pulse` builds one by its command-line name.

Amplitudes are magnitudes (≥ 0). A pulse of the opposite sign is not accepted: for the
symmetric structures of this toolkit the response to −ü_g is the mirror image
(θ → −θ, u → −u) of the response to +ü_g, so overturning maps need only a ≥ 0.

Recorded accelerograms are in `multimass.inputs.records` (`Record`).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from ..errors import InputError
from ..validation import number, positive
from . import pulse_shapes as ps
from .units import G

__all__ = [
    "Excitation",
    "FreeRelease",
    "SineWave",
    "CosineWave",
    "CosinePulse",
    "Ricker",
    "MPPulse",
    "MPShape",
    "PULSE_NAMES",
    "pulse",
    "MP_MAX_GAMMA",
    "MAX_PULSE_ACCELERATION",
    "plausible_amplitude",
]

TWO_PI = 2.0 * math.pi


# ---------------------------------------------------------------------------- validation
def _finite(name: str, value, what: str) -> float:
    return number(name, value, what=what)


def _finite_duration(cls_name: str, duration: float, fix: str) -> None:
    """A pulse must end: ω = 5e-324 or t0 = 1e308 make an infinite or overflowing duration."""
    if not math.isfinite(duration):
        raise InputError(f"{cls_name}: the pulse would last {duration!r} s; {fix}")


#: Largest pulse amplitude accepted (m/s²): 100 g. The largest ground accelerations ever
#: recorded are about 4 g (2008 Iwate–Miyagi, 2016 Kaikōura near the fault), and an
#: overturning map of a squat block (α ≈ 0.8) at a0/(α g) = 10 asks for 8 g; 100 g leaves
#: room for every study of rocking under earthquakes, while 1e300 g (a unit slip or a
#: typo) overflows the solver.
MAX_PULSE_ACCELERATION = 100.0 * G


def plausible_amplitude(
    name: str,
    value: float,
    what: str = "a pulse amplitude",
    fix: str = "check the value and its unit, e.g. 0.4g or 3.5m/s2",
) -> float:
    """`value` (m/s², finite) if its size is at most `MAX_PULSE_ACCELERATION`, else an
    `InputError` that names `name`, the value in g and the `fix`."""
    if abs(value) > MAX_PULSE_ACCELERATION:
        raise InputError(
            f"`{name}` = {value:.6g} m/s² ({value / G:.3g} g): {what} beyond "
            f"{MAX_PULSE_ACCELERATION / G:g} g, far above any earthquake (recorded peaks stay "
            f"below ~4 g); {fix}"
        )
    return value


def _amplitude(name: str, value) -> float:
    """A finite amplitude ≥ 0 (m/s²), at most `MAX_PULSE_ACCELERATION`."""
    x = _finite(name, value, "an amplitude in m/s²")
    if x < 0.0:
        raise InputError(
            f"`{name}` = {value!r}: an amplitude must be >= 0 (m/s²). To reverse the pulse, "
            f"pass {-x:g} and mirror the response (θ → −θ, u → −u): for a symmetric "
            f"structure the response to −ü_g is the mirror image of the response to +ü_g"
        )
    return plausible_amplitude(name, x)


def _positive(name: str, value, what: str) -> float:
    return positive(name, value, what)


# ---------------------------------------------------------------------------- base
class Excitation(ABC):
    """A horizontal ground acceleration ü_g(t) in m/s² (abstract base).

    Subclasses implement ``_scalar(t)`` (float → float) and ``_array(t)``
    (ndarray → ndarray), the `duration` property and `describe`.

    In a hot loop bind ``f = exc.acceleration`` once: calling the instance
    (``exc(t)``) goes through ``__call__`` and costs ~0.2 µs more per call.
    """

    kind = "excitation"

    @property
    @abstractmethod
    def duration(self) -> float:
        """Time (s) after which ü_g ≡ 0."""

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times (s) in [0, duration] where ü_g or its derivative jumps: start and end."""
        return (0.0, self.duration)

    @abstractmethod
    def _scalar(self, t: float) -> float: ...

    @abstractmethod
    def _array(self, t: np.ndarray) -> np.ndarray: ...

    def acceleration(self, t):
        """Ground acceleration ü_g(t) in m/s².

        Parameters
        ----------
        t : float or array_like
            Time(s) in s.

        Returns
        -------
        float or ndarray
            A float for a scalar `t`, else an array of the shape of `t`.
        """
        if isinstance(t, (float, int)):  # fast path; np.float64 is a float
            return self._scalar(float(t))
        arr = np.asarray(t, dtype=float)
        out = self._array(arr)
        return float(out) if arr.ndim == 0 else out

    __call__ = acceleration

    @abstractmethod
    def describe(self) -> dict:
        """A JSON-ready description: ``kind`` and the parameters in SI units."""


# names of earlier releases and of the papers' symbols -> the keyword to use now
_RENAMED = {
    "a0": "amplitude",
    "a_p": "amplitude",
    "a_g": "amplitude",
    "omega_p": "omega",
    "omega_g": "omega",
    "w": "omega",
}


class _Pulse(Excitation):
    """A pulse f(t) on the window 0 ≤ t ≤ duration, zero outside it.

    Constructed with keyword arguments only (``amplitude=``, ``omega=``, ...):
    a positional call or an old keyword raises `InputError` naming the fix.
    """

    def __new__(cls, *args, **kwargs):
        if args:
            raise InputError(
                f"{cls.__name__}{tuple(args)!r}: give the pulse by keyword, e.g. "
                f"{cls.__name__}(amplitude=0.4 * multimass.G, omega=15.0) (amplitude in m/s², "
                "omega in rad/s); positional arguments are refused so that an amplitude and "
                "a frequency cannot be swapped"
            )
        for old, new in _RENAMED.items():
            if old in kwargs:
                raise InputError(
                    f"{cls.__name__}: unknown keyword `{old}`; write `{new}=` "
                    f"(amplitude in m/s², omega in rad/s)"
                )
        return super().__new__(cls)

    @abstractmethod
    def _shape(self, t):
        """The pulse inside its window, on an array of times (numpy)."""

    @abstractmethod
    def _shape_scalar(self, t: float) -> float:
        """The same with `math` for a float (faster than numpy on scalars)."""

    def _scalar(self, t: float) -> float:
        if 0.0 <= t <= self.duration:
            return self._shape_scalar(t)
        return 0.0

    def _array(self, t: np.ndarray) -> np.ndarray:
        inside = (t >= 0.0) & (t <= self.duration)
        return np.where(inside, self._shape(t), 0.0)


# ---------------------------------------------------------------------------- free release
@dataclass(frozen=True)
class FreeRelease(Excitation):
    """No ground motion: the structure is released from an initial state.

    Parameters
    ----------
    theta0 : float, optional
        Initial base rotation θ0 (rad); θ0 > 0 leans onto the right pivot (paper 001,
        Fig 1). Only finiteness is checked here; the simulator checks ``|θ0| < α_cg``.
    u0 : None, float or sequence of float, optional
        Initial elastic displacements of nodes 1..N (m). ``None``: u = 0. A sequence:
        one value per node. A scalar: the static deflected shape under a lateral point
        load at the top node, u ∝ K⁻¹ e_N, scaled so that the top displacement is u0
        (see `initial_displacement`).
    """

    theta0: float = 0.0
    u0: float | tuple[float, ...] | None = None
    kind = "free_release"

    def __post_init__(self):
        object.__setattr__(self, "theta0", _finite("theta0", self.theta0, "an angle in rad"))
        u0 = self.u0
        if u0 is None:
            return
        if np.ndim(u0) == 0:
            object.__setattr__(self, "u0", _finite("u0", u0, "a top displacement in m"))
            return
        arr = np.asarray(u0)
        if arr.ndim != 1:
            raise InputError(
                f"`u0` has shape {arr.shape}: expected a scalar (top displacement, "
                f"m) or a 1-D sequence with one displacement per node 1..N"
            )
        values = tuple(_finite(f"u0[{i}]", v, "a displacement in m") for i, v in enumerate(u0))
        object.__setattr__(self, "u0", values)

    @property
    def duration(self) -> float:
        return 0.0

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return ()

    def _scalar(self, t: float) -> float:
        return 0.0

    def _array(self, t: np.ndarray) -> np.ndarray:
        return np.zeros_like(t)

    def initial_displacement(self, structure) -> np.ndarray:
        """The initial elastic displacements u(0) of nodes 1..N (m), shape (N,).

        Parameters
        ----------
        structure : Structure
            Supplies ``n`` (N) and the condensed full-contact stiffness ``K`` (N × N).

        Raises
        ------
        InputError
            If a vector `u0` does not have N entries, or a non-zero `u0` is given for a
            structure without elastic nodes (N = 0, a rigid block).
        """
        n = int(structure.n)
        name = getattr(structure, "name", "the structure")
        if self.u0 is None:
            return np.zeros(n)
        if isinstance(self.u0, tuple):
            if len(self.u0) != n:
                raise InputError(
                    f"`u0` has {len(self.u0)} values but {name} has N = {n} elastic nodes; "
                    f"give one displacement per node 1..N (m), or a scalar top displacement"
                )
            return np.array(self.u0, dtype=float)
        if self.u0 == 0.0:
            return np.zeros(n)
        if n == 0:
            raise InputError(
                f"`u0` = {self.u0!r}: {name} has no elastic nodes (N = 0, a rigid block), so it "
                f"cannot start deformed; pass u0=None and release it with theta0 instead"
            )
        e_top = np.zeros(n)
        e_top[-1] = 1.0
        shape = np.linalg.solve(np.asarray(structure.K, dtype=float), e_top)  # u = K⁻¹ e_N
        if not np.all(np.isfinite(shape)) or shape[-1] <= 0.0:
            raise InputError(
                f"`structure.K` of {name}: its static deflection under a top load "
                f"is not positive; check the stiffness matrix"
            )
        return shape * (self.u0 / shape[-1])

    def describe(self) -> dict:
        u0 = list(self.u0) if isinstance(self.u0, tuple) else self.u0
        return {"kind": self.kind, "theta0": self.theta0, "u0": u0, "duration": 0.0}


# ---------------------------------------------------------------------------- harmonic waves
@dataclass(frozen=True, kw_only=True)
class _SingleWave(_Pulse):
    """One period of ü_g = a0 f(ω t), zero outside 0 ≤ t ≤ 2π/ω (paper 004, Fig 2).

    Subclasses choose f (`_np_f` for arrays, `_math_f` for scalars) and `kind`.
    """

    amplitude: float
    omega: float

    def __post_init__(self):
        object.__setattr__(self, "amplitude", _amplitude("amplitude", self.amplitude))
        object.__setattr__(self, "omega", _positive("omega", self.omega, "rad/s"))
        _finite_duration(
            type(self).__name__,
            self.duration,
            f"`omega` = {self.omega!r} rad/s is too small; give ω in rad/s",
        )

    @property
    def duration(self) -> float:
        return TWO_PI / self.omega

    def _shape(self, t):
        return self.amplitude * self._np_f(self.omega * t)  # paper 004, Fig 2

    def _shape_scalar(self, t: float) -> float:
        return self.amplitude * self._math_f(self.omega * t)  # paper 004, Fig 2

    def describe(self) -> dict:
        return {
            "kind": self.kind,
            "amplitude": self.amplitude,
            "omega": self.omega,
            "duration": self.duration,
        }


@dataclass(frozen=True, kw_only=True)
class SineWave(_SingleWave):
    """A single sine wave ü_g = a0 sin(ω t) for 0 ≤ t ≤ 2π/ω, zero otherwise.

    Paper 004, Section 2.1 and Fig 2. ü_g is continuous at both ends; its derivative
    jumps there (breakpoints 0 and 2π/ω). Keyword arguments only:
    ``SineWave(amplitude=0.4 * G, omega=15.0)``.

    Parameters
    ----------
    amplitude : float
        Amplitude a0 (m/s², ≥ 0).
    omega : float
        Angular frequency ω = 2π/t_b (rad/s, > 0).
    """

    kind = "sine_wave"
    _np_f, _math_f = staticmethod(np.sin), staticmethod(math.sin)


@dataclass(frozen=True, kw_only=True)
class CosineWave(_SingleWave):
    """A single cosine wave ü_g = a0 cos(ω t) for 0 ≤ t ≤ 2π/ω, zero otherwise.

    Paper 004, Section 2.1 and Fig 2. ü_g jumps from 0 to a0 at t = 0 and from a0
    to 0 at t = 2π/ω (breakpoints); at those two instants it takes the value a0.
    Keyword arguments only: ``CosineWave(amplitude=..., omega=...)``.

    Parameters
    ----------
    amplitude : float
        Amplitude a0 (m/s², ≥ 0).
    omega : float
        Angular frequency (rad/s, > 0).
    """

    kind = "cosine_wave"
    _np_f, _math_f = staticmethod(np.cos), staticmethod(math.cos)


@dataclass(frozen=True, kw_only=True)
class CosinePulse(_Pulse):
    """Paper 001's "phased and vertically translated cosine pulse" (Section 4.4).

    Decided reading: the phrase describes the shake-table *displacement*,
    d(t) = (A/ω²)(1 − cos ω t) for 0 ≤ t ≤ 2π/ω — a cosine phased by π and
    translated up so that the table starts and ends at rest, at the same place
    (the only kind of pulse a table can play; paper 004 Section 4.2 makes the
    same point). The ground acceleration is then ü_g = A cos ω t over one
    period: paper 004's single cosine wave, with amplitude A. (A one-sided
    acceleration pulse peaking at A would leave the table moving, and with
    paper 001's A = 0.4 g, barely above S1's g tan α_cg = 0.36 g, it would hardly
    rock the specimen, unlike the paper's Figs 9–10.) ü_g jumps at both ends
    (breakpoints). Keyword arguments only:
    ``CosinePulse(amplitude=0.4 * G, omega=15.0)``.

    Parameters
    ----------
    amplitude : float
        Acceleration amplitude A (m/s², ≥ 0).
    omega : float
        Angular frequency (rad/s, > 0); the pulse lasts 2π/ω.
    """

    amplitude: float
    omega: float
    kind = "cosine_pulse"

    def __post_init__(self):
        object.__setattr__(self, "amplitude", _amplitude("amplitude", self.amplitude))
        object.__setattr__(self, "omega", _positive("omega", self.omega, "rad/s"))
        _finite_duration(
            "CosinePulse",
            self.duration,
            f"`omega` = {self.omega!r} rad/s is too small; give ω in rad/s",
        )

    @property
    def duration(self) -> float:
        return TWO_PI / self.omega

    def _shape(self, t):
        return self.amplitude * np.cos(self.omega * t)  # paper 001, Sec 4.4 (decided reading)

    def _shape_scalar(self, t: float) -> float:
        return self.amplitude * math.cos(self.omega * t)  # paper 001, Sec 4.4 (decided reading)

    def displacement(self, t):
        """Table displacement d(t) = (A/ω²)(1 − cos ω t) during the pulse (m)."""
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration)
        return self.amplitude / self.omega**2 * (1.0 - np.cos(self.omega * t))

    def describe(self) -> dict:
        return {
            "kind": self.kind,
            "amplitude": self.amplitude,
            "omega": self.omega,
            "duration": self.duration,
        }


# ---------------------------------------------------------------------------- Ricker
# Default ω_p t0: the root of |1 − x²/2| exp(−x²/4) = 1e-6 is x = 8.32633 (closed form of the
# wavelet's tail, decreasing for x > √6); rounded up to 3 decimals it leaves |ü_g(0)| ≈ 0.997e-6 a_p.
RICKER_X0 = 8.327


@dataclass(frozen=True, kw_only=True)
class Ricker(_Pulse):
    """A symmetric Ricker wavelet, centred at t0 and truncated to [0, 2 t0].

    ü_g = a_p (1 − ω_p² (t − t0)²/2) exp(−ω_p² (t − t0)²/4), the form used in the
    rocking literature (Vassiliou & Makris; paper 000, Section 4, Fig 6, with
    a_g and ω_g). Keyword arguments only: ``Ricker(amplitude=..., omega=...)``.

    Parameters
    ----------
    amplitude : float
        Peak acceleration a_p at t = t0 (m/s², ≥ 0).
    omega : float
        Characteristic angular frequency ω_p (rad/s, > 0).
    t0 : float, optional
        Centre of the wavelet (s, > 0). Default: t0 = 8.327/ω_p, so that
        ``|ü_g(0)| = |ü_g(2 t0)| < 1e-6 a_p`` (≈ 0.997e-6 a_p): the jumps at the
        truncation points 0 and 2 t0 are negligible. duration = 2 t0.
    """

    amplitude: float
    omega: float
    t0: float | None = None
    kind = "ricker"

    def __post_init__(self):
        object.__setattr__(self, "amplitude", _amplitude("amplitude", self.amplitude))
        object.__setattr__(self, "omega", _positive("omega", self.omega, "rad/s"))
        if self.t0 is None:
            object.__setattr__(self, "t0", RICKER_X0 / self.omega)
        else:
            object.__setattr__(self, "t0", _positive("t0", self.t0, "the centre time in s"))
        _finite_duration(
            "Ricker",
            self.duration,
            f"`t0` = {self.t0!r} s (or ω) gives no finite window [0, 2 t0]; give t0 in s",
        )

    @property
    def duration(self) -> float:
        return 2.0 * self.t0

    def _shape(self, t):
        x2 = (self.omega * (t - self.t0)) ** 2  # the bracket is bounded by 1: no inf·0
        return self.amplitude * ((1.0 - 0.5 * x2) * np.exp(-0.25 * x2))  # Ricker wavelet

    def _shape_scalar(self, t: float) -> float:
        x2 = (self.omega * (t - self.t0)) ** 2
        return self.amplitude * ((1.0 - 0.5 * x2) * math.exp(-0.25 * x2))  # Ricker wavelet

    def describe(self) -> dict:
        return {
            "kind": self.kind,
            "amplitude": self.amplitude,
            "omega": self.omega,
            "t0": self.t0,
            "duration": self.duration,
        }


# ---------------------------------------------------------------------------- M&P pulse
#: Largest plausible amplitude of a velocity pulse (m/s); recorded near-fault PGVs stay
#: below ~3 m/s, so a larger value is almost surely cm/s or an acceleration.
MP_MAX_AMPLITUDE = 20.0
#: Highest plausible pulse frequency f_p (Hz): near-fault pulses last 0.5–10 s; a value
#: above this is almost surely ω in rad/s.
MP_MAX_FP = 50.0
#: Largest γ of an M&P pulse: M&P 2003 fitted γ of 1.5–3 to recorded near-fault pulses; the
#: window holds about γ half-cycles, and past 10 it is a harmonic wave, not a pulse (its
#: peak search and the run's samples grow with γ: 1e6 runs out of memory).
MP_MAX_GAMMA = 10.0


@dataclass(frozen=True, kw_only=True)
class MPPulse(Excitation):
    """The Mavroeidis–Papageorgiou (2003) near-fault velocity pulse, as an excitation.

    Ground velocity (M&P 2003, BSSA 93(3) 1099–1131):
    ``v(t) = A/2 [1 + cos(2π f_p (t − t0)/γ)] cos(2π f_p (t − t0) + ν)`` for
    ``|t − t0| ≤ γ/(2 f_p)``, zero outside; the ground acceleration ü_g is its exact
    derivative and the displacement its exact integral (closed forms in
    `multimass.inputs.pulse_shapes`, the one source the solve_ivp and compiled paths
    evaluate). ü_g is continuous at both ends of the window (breakpoints), the
    velocity is zero there; the displacement keeps a residual offset after the pulse
    unless the pulse is antisymmetric in velocity. Keyword arguments only, with the
    paper's symbols: ``MPPulse(amplitude=0.6, fp=0.5, gamma=2.0, nu=0.0)``.

    Parameters
    ----------
    amplitude : float
        A, the velocity amplitude (m/s, ≥ 0); with ν = 0 the peak ground velocity.
    fp : float
        f_p, the prevailing (pulse) frequency (Hz, > 0); the pulse period is 1/f_p.
    gamma : float, optional
        γ > 1, the oscillatory character: the window lasts γ/f_p (default 2).
    nu : float, optional
        ν, the phase of the carrier (rad, within ±2π; default 0: a velocity pulse
        symmetric about t0; ±π/2 makes it antisymmetric).
    t0 : float, optional
        Time of the envelope's peak (s). Default γ/(2 f_p): the pulse starts at t = 0.
        A smaller t0 would start it before the simulation and is refused.
    check_units : bool, optional
        Refuse A > 20 m/s and f_p > 50 Hz as likely unit slips (cm/s, rad/s). Default
        True; `MPShape` turns it off, since it derives A from a peak acceleration on
        dimensionless grids that may reach such values.

    Notes
    -----
    ``duration`` = t0 + γ/(2 f_p). `peak_acceleration` is the exact peak of ``|ü_g|`` (the
    pulse's PGA), used by `MPShape` and the dimensionless fragility (a_p/(g tan α)).
    """

    amplitude: float
    fp: float
    gamma: float = 2.0
    nu: float = 0.0
    t0: float | None = None
    check_units: bool = field(default=True, repr=False, compare=False)
    kind = "mp_pulse"

    def __new__(cls, *args, **kwargs):
        if args:
            raise InputError(
                f"MPPulse{tuple(args)!r}: give the pulse by keyword, e.g. MPPulse(amplitude=0.6, "
                "fp=0.5, gamma=2.0, nu=0.0) (amplitude in m/s, fp in Hz, nu in rad)"
            )
        return super().__new__(cls)

    def __post_init__(self):
        a = _finite("amplitude", self.amplitude, "a velocity amplitude in m/s")
        if a < 0.0:
            raise InputError(
                f"`amplitude` = {self.amplitude!r}: must be >= 0 (m/s); reverse the pulse "
                f"with the phase instead: nu + π"
            )
        if self.check_units and a > MP_MAX_AMPLITUDE:
            raise InputError(
                f"`amplitude` = {self.amplitude!r} m/s is above {MP_MAX_AMPLITUDE:g} m/s, far "
                "beyond any recorded pulse: give the velocity amplitude A in m/s (a value in "
                "cm/s divided by 100; an acceleration amplitude through MPShape)"
            )
        fp = _positive("fp", self.fp, "the pulse frequency in Hz")
        if self.check_units and fp > MP_MAX_FP:
            raise InputError(
                f"`fp` = {self.fp!r} Hz: above {MP_MAX_FP:g} Hz; give f_p in Hz "
                f"(ω_p / 2π = {fp / TWO_PI:.6g} Hz if this was ω_p in rad/s)"
            )
        gamma = _finite("gamma", self.gamma, "the oscillatory character γ")
        if not 1.0 < gamma <= MP_MAX_GAMMA:
            raise InputError(
                f"`gamma` = {self.gamma!r}: the M&P pulse needs 1 < γ ≤ {MP_MAX_GAMMA:g} "
                "(M&P 2003; recorded pulses fit 1.5–3; a larger γ is a harmonic wave, not a "
                "pulse); give e.g. gamma=2.0"
            )
        nu = _finite("nu", self.nu, "a phase in rad")
        if abs(nu) > TWO_PI:
            raise InputError(
                f"`nu` = {self.nu!r}: the phase ν is in rad, within ±2π; "
                f"{nu:g}° is {math.radians(nu):.6g} rad"
            )
        half = gamma / (2.0 * fp)
        t0 = half if self.t0 is None else _finite("t0", self.t0, "the envelope's peak time in s")
        if t0 < half * (1.0 - 1e-12):
            raise InputError(
                f"`t0` = {self.t0!r} s: the pulse would start at t0 − γ/(2 f_p) = "
                f"{t0 - half:.6g} s, before the run; give t0 >= {half:.6g} s (or leave it out)"
            )
        for name, value in (("amplitude", a), ("fp", fp), ("gamma", gamma), ("nu", nu)):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "t0", float(t0))
        _finite_duration("MPPulse", self.duration, "give t0 in s and fp in Hz")

    # -- window ------------------------------------------------------------------------------
    @property
    def half_width(self) -> float:
        """γ/(2 f_p): the half-length of the pulse's window (s)."""
        return self.gamma / (2.0 * self.fp)

    @property
    def start(self) -> float:
        """t0 − γ/(2 f_p): when the pulse starts (s)."""
        return max(0.0, self.t0 - self.half_width)

    @property
    def duration(self) -> float:
        return self.t0 + self.half_width

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return (self.start, self.duration)

    def _args(self) -> tuple[float, float, float, float, float]:
        return (self.amplitude, self.fp, self.gamma, self.nu, self.t0)

    def _window(self, fn, t):
        t = np.asarray(t, dtype=float)
        inside = (t >= self.start) & (t <= self.duration)
        vals = np.frompyfunc(lambda x: fn(x, *self._args()), 1, 1)(np.where(inside, t, self.t0))
        out = np.where(inside, np.asarray(vals, dtype=float), 0.0)
        return float(out) if out.ndim == 0 else out

    # -- ü_g, v, d ---------------------------------------------------------------------------
    def _scalar(self, t: float) -> float:
        if self.start <= t <= self.duration:
            return ps.mp_acceleration(t, *self._args())
        return 0.0

    def _array(self, t: np.ndarray) -> np.ndarray:
        return np.asarray(self._window(ps.mp_acceleration, t), dtype=float)

    def velocity(self, t):
        """Ground velocity v(t) (m/s): M&P 2003's closed form, zero outside the window."""
        return self._window(ps.mp_velocity, t)

    def displacement(self, t):
        """Ground displacement d(t) (m) from rest at the start: the exact integral of v.

        After the pulse it keeps its final (residual) value.
        """
        t = np.clip(np.asarray(t, dtype=float), self.start, self.duration)
        d0 = ps.mp_displacement_raw(self.start, *self._args())
        out = self._window(ps.mp_displacement_raw, t) - d0
        return float(out) if np.ndim(out) == 0 else out

    @property
    def peak_acceleration(self) -> float:
        """max ``|ü_g|`` over the pulse (m/s²): A f_p times the peak of the unit pulse."""
        return self.amplitude * self.fp * _unit_peak(self.gamma, self.nu)

    def describe(self) -> dict:
        return {
            "kind": self.kind,
            "amplitude": self.amplitude,
            "fp": self.fp,
            "gamma": self.gamma,
            "nu": self.nu,
            "t0": self.t0,
            "duration": self.duration,
            "peak_acceleration": self.peak_acceleration,
        }


@lru_cache(maxsize=256)
def _unit_peak(gamma: float, nu: float) -> float:
    """max ``|ü_g|`` of the M&P pulse with A = 1 m/s, f_p = 1 Hz (m/s²): ü_g scales as A·f_p.

    A grid over the window with ~100 points per lobe of ``|ü_g|`` (the window holds γ carrier
    periods, two lobes each), then a bounded golden-section search around the largest
    sample, on the same `mp_acceleration` the runs evaluate.
    """
    from scipy.optimize import minimize_scalar

    half = gamma / 2.0
    acc = np.frompyfunc(lambda x: abs(ps.mp_acceleration(x, 1.0, 1.0, gamma, nu, 0.0)), 1, 1)
    grid = np.linspace(-half, half, max(401, int(200 * gamma) + 1))
    vals = acc(grid).astype(float)
    i = int(np.argmax(vals))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    res = minimize_scalar(
        lambda x: -abs(ps.mp_acceleration(x, 1.0, 1.0, gamma, nu, 0.0)),
        bounds=(lo, hi),
        method="bounded",
        options={"xatol": 1e-12 * max(1.0, half)},
    )
    return float(max(vals[i], -res.fun))


@dataclass(frozen=True)
class MPShape:
    """A family of M&P pulses of one shape (γ, ν), built like the other pulses.

    ``MPShape(gamma=2, nu=0)(amplitude=a_p, omega=ω_p)`` is the `MPPulse` with
    f_p = ω_p/2π whose *peak ground acceleration* is a_p (m/s²), starting at t = 0 — so
    maps and spectra sweep M&P pulses over (ω_p/p, a_p/(g tan α)) exactly as they sweep
    sine and Ricker pulses (the variables of Dimitrakopoulos & Paraskeva 2015, with
    a_p read as the pulse's PGA).

    Parameters
    ----------
    gamma : float
        γ > 1.
    nu : float
        ν in rad.
    """

    gamma: float = 2.0
    nu: float = 0.0
    kind = "mp"

    def __post_init__(self):
        probe = MPPulse(amplitude=1.0, fp=1.0, gamma=self.gamma, nu=self.nu)  # validates
        object.__setattr__(self, "gamma", probe.gamma)
        object.__setattr__(self, "nu", probe.nu)

    def velocity_amplitude(self, amplitude: float, omega: float) -> float:
        """The A (m/s) of the pulse with peak acceleration `amplitude` at ω_p = `omega`."""
        fp = omega / TWO_PI
        return amplitude / (fp * _unit_peak(self.gamma, self.nu))

    def __call__(self, *, amplitude: float, omega: float) -> MPPulse:
        a = _amplitude("amplitude", amplitude)
        w = _positive("omega", omega, "rad/s")
        return MPPulse(
            amplitude=self.velocity_amplitude(a, w),
            fp=w / TWO_PI,
            gamma=self.gamma,
            nu=self.nu,
            check_units=False,
        )

    def describe(self) -> dict:
        return {"kind": self.kind, "gamma": self.gamma, "nu": self.nu}


# ---------------------------------------------------------------------------- by name
#: Pulse names of the command line and of sweeps, for `pulse`.
PULSE_NAMES = ("sine", "cosine", "ricker", "mp")


def pulse(
    name: str,
    *,
    amplitude: float,
    omega: float,
    structure_kind: str = "column",
    gamma: float = 2.0,
    nu: float = 0.0,
) -> Excitation:
    """A pulse by its command-line name.

    Parameters
    ----------
    name : {"sine", "cosine", "ricker", "mp"}
        "cosine" is paper 001's `CosinePulse` for a column and paper 004's
        `CosineWave` for a block (the same ground acceleration, A cos ω t over
        one period; the two papers name it differently). "mp" is the M&P pulse
        (`MPShape`): `amplitude` its peak acceleration, `omega` = 2π f_p.
    amplitude : float
        m/s² (the peak acceleration).
    omega : float
        rad/s.
    structure_kind : {"column", "block"}, optional
        Chooses the cosine's name (see above).
    gamma, nu : float, optional
        The M&P pulse's γ and ν (rad); only with "mp".

    Raises
    ------
    InputError
        For an unknown name or an invalid amplitude or frequency.
    """
    if name == "sine":
        return SineWave(amplitude=amplitude, omega=omega)
    if name == "cosine":
        cls = CosinePulse if structure_kind == "column" else CosineWave
        return cls(amplitude=amplitude, omega=omega)
    if name == "ricker":
        return Ricker(amplitude=amplitude, omega=omega)
    if name == "mp":
        return MPShape(gamma=gamma, nu=nu)(amplitude=amplitude, omega=omega)
    raise InputError(f"`pulse` = {name!r}: use one of {', '.join(PULSE_NAMES)}")
