"""The flexible rocking oscillator with Poisson impacts (paper 000, Section 4).

A lumped mass m on a flexible column (mass m_c, height h, stiffness EI,
shape ψ of Eq 26) standing on a rigid base (mass m_b, width 2b) that can
rock, bounce or fly on a rigid ground. Coordinates q = (u, x, y, φ), φ
counter-clockwise positive as in paper 000 (the toolkit's θ = −φ); contact 0
is the left base corner, contact 1 the right one: phase +1 (result contract,
`multimass.result`) rocks on the right corner, −1 on the left, 0 is full
contact, None flight; ``|φ|`` = π/2 is an event "overturn". The equations of motion come from
`multimass.model.flexible_oscillator_eom` (SymPy, Lagrangian of Eq 30); phases and
impacts from `multimass.engines.contact_dynamics` and `impact_models.poisson_impact`.

Decided readings of the paper (its Eqs 27–30 are partly garbled):

* Eq 27 prints α3²/3 in m̃; ∫ψ² gives α3²/7, so m̃ = m + (33/140) m_c for
  the adopted shape (α2 = 3/2, α3 = −1/2), not the printed formula's value.
* Eq 28 prints (1 + 31/140 γ_mc) where the derivation (and Eq 29, which it must
  reduce to with ω_n² = k̃/m̃) needs m̃/m = 1 + 33/140 γ_mc. `uplift_margin`
  uses m̃/m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import sympy as sp

from ..errors import InputError
from ..model.flexible_oscillator_eom import numeric, symbolic
from ..validation import number, positive
from ._contact_checks import ground_excitation
from .contact_dynamics import ContactResponse, ContactView, simulate_contacts

__all__ = ["FlexibleOscillator", "OscillatorResponse", "simulate_oscillator"]

SHAPE = (0.0, 0.0, 1.5, -0.5)  # α0, α1, α2, α3: paper 000, Sec 4 (Chopra)


def _shape(value) -> tuple[float, float, float, float]:
    """(α0, α1, α2, α3) of Eq 26 as floats, finite, ψ(h) = Σα = 1, with stiffness."""
    need = (
        "expected four finite numbers (α0, α1, α2, α3) with ψ(h) = α0 + α1 + α2 + α3 "
        "= 1 (u is the top deflection), e.g. (0, 0, 1.5, -0.5)"
    )
    try:
        shape = tuple(float(a) for a in value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"`shape` = {value!r}: {need}") from None
    if len(shape) != 4 or not all(map(math.isfinite, shape)) or abs(sum(shape) - 1.0) > 1e-12:
        raise InputError(f"`shape` = {value!r}: {need}")
    a2, a3 = shape[2], shape[3]
    if not 3 * a3 * a3 + a2 * a2 + 3 * a3 * a2 > 0.0:  # k̃ > 0, paper 000, Eq 27
        raise InputError(
            f"`shape` = {value!r}: ψ'' ≡ 0, so the column has no stiffness "
            "(k̃ = 0, Eq 27); give α2 or α3 ≠ 0"
        )
    return shape


def _check_derived(osc) -> None:
    """m̃, k̃, ω_n, c, L0, L1 finite and positive where they must be (Eq 27), else InputError.

    Evaluated with exact polynomial integrals of ψ(s) = Σ α_i s^i over s ∈ [0, 1], apart
    from the SymPy derivation the properties use.
    """
    psi = np.polynomial.Polynomial(osc.shape)
    integral = lambda p: float(p.integ()(1.0))  # noqa: E731
    a2, a3 = osc.shape[2], osc.shape[3]
    try:
        with np.errstate(all="ignore"):
            m_t = osc.m + osc.m_c * integral(psi * psi)
            k_t = osc.EI / osc.h**3 * 4.0 * (3 * a3 * a3 + a2 * a2 + 3 * a3 * a2)  # Eq 27
            values = dict(
                m_tilde=m_t,
                k_tilde=k_t,
                omega_n=math.sqrt(k_t / m_t) if m_t > 0 and k_t >= 0 else 0.0,
                c=2.0 * osc.zeta * math.sqrt(m_t * k_t) if m_t * k_t >= 0 else 0.0,
                L0=osc.m_c * integral(psi),
                L1=osc.m_c * integral(psi * np.polynomial.Polynomial([0, 1])),
                total_weight=(osc.m + osc.m_c + osc.m_b) * osc.g,
            )
        bad = [
            k
            for k, v in values.items()
            if not math.isfinite(v) or (k in ("m_tilde", "k_tilde", "omega_n") and not v > 0.0)
        ]
    except (OverflowError, ZeroDivisionError):
        bad = ["quantities"]
    if bad:
        raise InputError(
            f"FlexibleOscillator(m={osc.m!r}, m_c={osc.m_c!r}, m_b={osc.m_b!r}, "
            f"h={osc.h!r}, EI={osc.EI!r}, zeta={osc.zeta!r}): derived "
            f"{', '.join(bad)} not finite and positive; give SI values of "
            "ordinary size (kg, m, N m²)"
        )


@dataclass(frozen=True)
class FlexibleOscillator:
    """Flexible rocking oscillator of paper 000, Fig 2b.

    Parameters
    ----------
    m, m_c, m_b : float
        Lumped top mass, column mass (may be 0) and base mass (kg).
    h : float
        Column height (m).
    b : float
        Half-width of the base (m).
    EI : float
        Flexural rigidity of the column (N m²).
    zeta : float
        Damping ratio of the fixed-base vibration.
    g : float
    shape : tuple of float
        (α0, α1, α2, α3) of Eq 26, with ψ(h) = 1.
    """

    m: float
    m_c: float
    m_b: float
    h: float
    b: float
    EI: float
    zeta: float = 0.0
    g: float = 9.81
    shape: tuple = SHAPE

    def __post_init__(self):
        for name in ("m", "h", "b", "EI", "g"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))
        for name in ("m_c", "m_b", "zeta"):
            object.__setattr__(self, name, number(name, getattr(self, name), low=0.0))
        object.__setattr__(self, "shape", _shape(self.shape))
        _check_derived(self)

    @classmethod
    def from_frequency(cls, f_n: float, **kw) -> FlexibleOscillator:
        """Oscillator whose fixed-base frequency √(k̃/m̃)/2π is `f_n` (Hz)."""
        probe = cls(EI=1.0, **kw)
        k = (2.0 * math.pi * positive("f_n", f_n)) ** 2 * probe.m_tilde
        return cls(EI=k / probe.k_tilde, **kw)

    def _coef(self, name):
        s = symbolic(tuple(sp.nsimplify(a) for a in self.shape))
        expr = getattr(s, name)
        P = s.params
        return float(expr.subs({P["m"]: self.m, P["m_c"]: self.m_c, P["h"]: self.h}))

    @cached_property
    def m_tilde(self) -> float:
        """Generalised mass m̃ = m + (m_c/h)∫ψ² dξ (paper 000, Eq 27, corrected)."""
        return self._coef("m_tilde")

    @cached_property
    def k_tilde(self) -> float:
        """Generalised stiffness k̃ = ∫EI ψ''² dξ (paper 000, Eq 27)."""
        return self.EI / self.h**3 * self._coef("k_tilde_factor")

    @cached_property
    def omega_n(self) -> float:
        """Fixed-base circular frequency √(k̃/m̃) (rad/s)."""
        return math.sqrt(self.k_tilde / self.m_tilde)

    @cached_property
    def c(self) -> float:
        """Damping coefficient 2ζ√(m̃ k̃) (paper 000, Eq 28)."""
        return 2.0 * self.zeta * math.sqrt(self.m_tilde * self.k_tilde)

    @property
    def alpha(self) -> float:
        """Slenderness atan(b/h) (paper 000, Sec 4)."""
        return math.atan2(self.b, self.h)

    @cached_property
    def L0(self) -> float:
        """(m_c/h)∫ψ dξ: 3/8 m_c for the adopted shape."""
        return self._coef("L0")

    @cached_property
    def L1(self) -> float:
        """(m_c/h²)∫ψ ξ dξ: 11/40 m_c for the adopted shape."""
        return self._coef("L1")

    def params(self) -> tuple:
        return (self.m, self.m_c, self.m_b, self.h, self.b, self.g, self.k_tilde, self.c)

    def uplift_margin(self, u: float, udot: float, ag: float) -> float:
        """Left-hand side of Eq 28: ≥ 0 when rocking about the right corner starts.

        With γ = m_c/m and the corrected m̃/m (module docstring).
        """
        m, g, hb = self.m, self.g, self.h / self.b
        l1, l0 = 1.0 + self.L1 / m, 1.0 + self.L0 / m
        mt = self.m_tilde / m
        return (
            hb * l1 / mt * (self.c * udot / (m * g) + self.k_tilde * u / (m * g) + l0 * ag / g)
            - (1.0 + self.m_b / m + self.m_c / m)
            - hb * (1.0 + 0.5 * self.m_c / m) * ag / g
            + l0 * u / self.b
        )  # paper 000, Eq 28

    @cached_property
    def u_cr(self) -> float:
        """Static deflection that starts rocking (paper 000, Eq 29)."""
        m, g = self.m, self.g
        return (
            (1.0 + self.m_b / m + self.m_c / m)
            * self.b
            * g
            / ((1.0 + self.L1 / m) * self.h * self.omega_n**2 + (1.0 + self.L0 / m) * g)
        )  # paper 000, Eq 29


class _OscillatorModel:
    """`contact_dynamics` model of the oscillator."""

    n, k = 4, 2
    rotation = 3  # q[3] = φ, counter-clockwise: θ = −φ
    pivots = (0, 1)  # contact 0 the left base corner, contact 1 the right one

    def __init__(self, osc: FlexibleOscillator, ag, quiet_after: float):
        self.o, self.ag, self.quiet_after = osc, ag, quiet_after
        self.f = numeric(osc.shape)
        self.p = osc.params()
        self.c = osc.c
        self.events = (("overturn", lambda t, q, v: abs(q[3]) - 0.5 * math.pi),)

    def mass(self, q):
        return np.asarray(self.f["M"](q, self.p), dtype=float)

    def forces(self, t, q, v):
        return np.array(self.f["forcing"](q, v, self.ag(t), self.p))

    def contacts(self, q, v):
        b, c, sn, w = self.o.b, math.cos(q[3]), math.sin(q[3]), v[3]
        s = np.array([-1.0, 1.0])
        z, one = np.zeros(2), np.ones(2)
        g = q[2] + s * b * sn
        WN = np.array([z, z, one, s * b * c])
        WT = np.array([z, one, z, -s * b * sn])
        return g, WN, WT, -s * b * sn * w * w, -s * b * c * w * w

    def energy(self, q, v):
        return self.f["energy"](q, v, self.p)

    def powers(self, t, q, v):
        return self.f["ground_power"](q, v, self.ag(t), self.p), self.c * v[0] ** 2


@dataclass(frozen=True, eq=False)
class OscillatorResponse(ContactView):
    """Response of `simulate_oscillator` with named views of the coordinates.

    A `multimass.result.Result` (engine "contact") through
    `multimass.engines.contact_dynamics.ContactView` (θ, θ̇ and the peaks are the base's);
    ``series`` names the coordinates u, x, y and φ.

    Attributes
    ----------
    oscillator : FlexibleOscillator
    eps_p : float
    raw : ContactResponse
    """

    oscillator: FlexibleOscillator
    eps_p: float
    raw: ContactResponse

    COORDINATES = ("u", "x", "y", "phi")
    u = property(lambda self: self.coordinate("u"), doc="Deflection of the column top (m).")
    x = property(lambda self: self.coordinate("x"))
    y = property(lambda self: self.coordinate("y"))
    phi = property(lambda self: self.coordinate("phi"), doc="Rotation, counter-clockwise.")

    def _summary_extra(self) -> dict:
        osc = self.oscillator
        return self.raw._summary_extra() | {
            "model": "flexible_oscillator",
            "eps_p": self.eps_p,
            "omega_n": osc.omega_n,
            "u_cr": osc.u_cr,
            "alpha": osc.alpha,
            "u_max": float(np.max(np.abs(self.u))) if self.t.size else 0.0,
        }


def simulate_oscillator(
    osc: FlexibleOscillator,
    eps_p: float,
    t_end: float,
    *,
    ag=None,
    u0: float = 0.0,
    udot0: float = 0.0,
    dt_out: float | None = 0.005,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    zeno_velocity: float | None = None,
    max_events: int = 20_000,
    mu: float | None = None,
) -> OscillatorResponse:
    """Event-driven response of the oscillator, starting with its base flat on the ground.

    Parameters
    ----------
    osc : FlexibleOscillator
    eps_p : float
        Poisson's coefficient ε_P ∈ [0, 1].
    t_end : float
    ag : callable, optional
        Ground acceleration ag(t) (m/s²), e.g. `multimass.Ricker`; ``duration`` and
        ``breakpoints`` attributes are honoured.
    u0, udot0 : float
        Initial deflection and rate of the column top (base at rest, flat). The
        base rocks from t = 0 when the contact forces say so (``|u0|`` beyond
        `FlexibleOscillator.u_cr`, Eq 29); the energy ledger starts from this
        state, ½ k̃ u0² + ½ m̃ u̇0².
    dt_out, rtol, atol, zeno_velocity, max_events
        As in `multimass.engines.contact_dynamics.simulate_contacts`; zeno_velocity
        defaults to 1e-4 √(g b).
    mu : float, optional
        Friction coefficient of the base corners: the run reports the largest
        friction demand ``|T/N|`` of its sticking corners (``friction``) and, when
        it exceeds `mu`, status "inaccurate" with a warning (the base would
        slide). None: reported, not checked.

    Returns
    -------
    OscillatorResponse
        ``status`` is the status of ``outcome`` ("completed", "overturned";
        "max_events" fails) when the checks pass, else "inaccurate"; "failed"
        when the solvers could not go on (history kept, ``message`` says why).
    """
    if not isinstance(osc, FlexibleOscillator):
        raise InputError(f"`osc` = {osc!r}: expected a FlexibleOscillator")
    ag, quiet, bps = ground_excitation(ag)
    u0, udot0 = number("u0", u0), number("udot0", udot0)
    eps_p = number("eps_p", eps_p)
    zv = 1e-4 * math.sqrt(osc.g * osc.b) if zeno_velocity is None else zeno_velocity
    q0 = np.array([u0, 0.0, 0.0, 0.0])
    v0 = np.array([udot0, 0.0, 0.0, 0.0])
    raw = simulate_contacts(
        _OscillatorModel(osc, ag, quiet),
        q0,
        v0,
        t_end,
        eps_p,
        dt_out=dt_out,
        rtol=rtol,
        atol=atol,
        gap_tol=1e-9 * osc.h,
        zeno_velocity=zv,
        max_events=max_events,
        breakpoints=bps,
        mu=mu,
    )
    return OscillatorResponse(osc, eps_p, raw)
