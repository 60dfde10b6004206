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
swapped silently (both are plain numbers in SI units: m/s² and rad/s).
`pulse` builds one by its command-line name.

Amplitudes are magnitudes (≥ 0). A pulse of the opposite sign is not accepted: for the
symmetric structures of this toolkit the response to −ü_g is the mirror image
(θ → −θ, u → −u) of the response to +ü_g, so overturning maps need only a ≥ 0.

Recorded accelerograms are in `multimass.records` (`Record`).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from .errors import InputError
from .validation import number, positive

__all__ = [
    "Excitation",
    "FreeRelease",
    "SineWave",
    "CosineWave",
    "CosinePulse",
    "Ricker",
    "PULSE_NAMES",
    "pulse",
]

TWO_PI = 2.0 * math.pi


# ---------------------------------------------------------------------------- validation
def _finite(name: str, value, what: str) -> float:
    return number(name, value, what=what)


def _finite_duration(cls_name: str, duration: float, fix: str) -> None:
    """A pulse must end: ω = 5e-324 or t0 = 1e308 make an infinite or overflowing duration."""
    if not math.isfinite(duration):
        raise InputError(f"{cls_name}: the pulse would last {duration!r} s; {fix}")


def _amplitude(name: str, value) -> float:
    """A finite amplitude ≥ 0 (m/s²)."""
    x = _finite(name, value, "an amplitude in m/s²")
    if x < 0.0:
        raise InputError(
            f"`{name}` = {value!r}: an amplitude must be >= 0 (m/s²). To reverse the pulse, "
            f"pass {-x:g} and mirror the response (θ → −θ, u → −u): for a symmetric "
            f"structure the response to −ü_g is the mirror image of the response to +ü_g"
        )
    return x


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


# ---------------------------------------------------------------------------- by name
#: Pulse names of the command line and of sweeps, for `pulse`.
PULSE_NAMES = ("sine", "cosine", "ricker")


def pulse(
    name: str, *, amplitude: float, omega: float, structure_kind: str = "column"
) -> Excitation:
    """A pulse by its command-line name.

    Parameters
    ----------
    name : {"sine", "cosine", "ricker"}
        "cosine" is paper 001's `CosinePulse` for a column and paper 004's
        `CosineWave` for a block (the same ground acceleration, A cos ω t over
        one period; the two papers name it differently).
    amplitude : float
        m/s².
    omega : float
        rad/s.
    structure_kind : {"column", "block"}, optional
        Chooses the cosine's name (see above).

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
    raise InputError(f"`pulse` = {name!r}: use one of {', '.join(PULSE_NAMES)}")
