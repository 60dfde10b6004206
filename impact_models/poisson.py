"""Impact as two linear complementarity problems with Poisson's law (paper 000, Eqs 1–12).

An instantaneous impact of a system with mass matrix ``M`` at closed contacts
with normal directions ``W_N`` and sticking tangential directions ``W_T`` is
split into a compression phase (LCP of Eq 6) and an expansion phase (LCP of
Eq 11). With generalised velocity ``u`` the contact velocities are
``ġ_N = W_Nᵀ u`` and ``ġ_T = W_Tᵀ u``; negative ``ġ_N`` means approach;
impulses are positive when compressive.

The impulse balance is ``M (u⁰ − u⁻) = W_N Λ_N⁰ + W_T Λ_T⁰`` (Eq 2) and
``M (u⁺ − u⁰) = W_N Λ_N⁺ + W_T Λ_T⁺`` (Eq 8); the paper prints a "+" between
the velocities, a typo (DESIGN.md).

Sticking: the paper assumes ġ_T⁻ = ġ_T⁰ = 0 (Eq 5). Here the tangential
impulse enforces ġ_T⁰ = 0 also when ġ_T⁻ ≠ 0 (a landing corner that slips is
stopped, as infinite friction would), which adds ``−G_TT⁻¹ ġ_T⁻`` to Eq 5 and
``−G_NT G_TT⁻¹ ġ_T⁻`` to the constant of Eq 6; both vanish when ġ_T⁻ = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .complementarity import LCPError, lemke

__all__ = ["PoissonImpact", "poisson_impact"]


@dataclass(frozen=True)
class PoissonImpact:
    """Result of a Poisson impact (paper 000, Eqs 1–12).

    Attributes
    ----------
    u_minus, u_compression, u_plus : ndarray, shape (n,)
        Generalised velocity before the impact, at the end of compression (u⁰)
        and after the impact (u⁺).
    impulse_compression, impulse_expansion : ndarray, shape (k_N,)
        Normal impulses Λ_N⁰ and Λ_N⁺ per contact (Λ_N⁺ = Λ_NP + ε Λ_N⁰).
    impulse_np : ndarray, shape (k_N,)
        The modified expansion impulse Λ_NP of Eq 11.
    tangential_impulse_compression, tangential_impulse_expansion : ndarray, shape (k_T,)
        Λ_T⁰ (Eq 5) and Λ_T⁺ (Eq 10).
    tangential_impulse : ndarray, shape (k_T,)
        Total Λ_T⁰ + Λ_T⁺.
    gN_minus, gN_compression, gN_plus : ndarray, shape (k_N,)
        Normal contact velocities ġ_N⁻, ġ_N⁰, ġ_N⁺.
    states : tuple of (str, str)
        Per contact, its state after compression and after expansion:
        ``"closed"`` (ġ_N = 0) or ``"separating"`` (ġ_N > 0).
    energy_loss : float
        Kinetic energy lost, ½u⁻ᵀMu⁻ − ½u⁺ᵀMu⁺. For one ε_P ∈ [0, 1] at all
        contacts it is ½(1 − ε²)Λ_N⁰ᵀAΛ_N⁰ + ½Λ_NPᵀAΛ_NP ≥ 0 (A of Eq 6); with
        per-contact ε_P no gain was found in random tests (not proved).
    eps_p : ndarray, shape (k_N,)
        Poisson coefficients used.
    solver : tuple of str
        Method that solved the compression and the expansion LCP: ``"lemke"``,
        or ``"nnls"`` when Lemke ended on a round-off ray (many redundant contacts).
    """

    u_minus: np.ndarray
    u_compression: np.ndarray
    u_plus: np.ndarray
    impulse_compression: np.ndarray
    impulse_expansion: np.ndarray
    impulse_np: np.ndarray
    tangential_impulse_compression: np.ndarray
    tangential_impulse_expansion: np.ndarray
    gN_minus: np.ndarray
    gN_compression: np.ndarray
    gN_plus: np.ndarray
    states: tuple[tuple[str, str], ...]
    energy_loss: float
    eps_p: np.ndarray
    solver: tuple[str, str] = ("lemke", "lemke")

    @property
    def tangential_impulse(self) -> np.ndarray:
        return self.tangential_impulse_compression + self.tangential_impulse_expansion

    @property
    def final_states(self) -> tuple[str, ...]:
        """State of each contact after the impact (after expansion)."""
        return tuple(s[1] for s in self.states)


def _matrix(name: str, value, shape=None) -> np.ndarray:
    a = np.array(value, dtype=float)  # a copy: results never alias the caller's arrays
    if not np.all(np.isfinite(a)):
        raise LCPError(f"`{name}` holds NaN or inf: pass finite numbers")
    if shape is not None and a.shape != shape:
        raise LCPError(f"`{name}` has shape {a.shape}: expected {shape}")
    return a


def _validate(M, W_N, W_T, u_minus, eps_p):
    import scipy.linalg as sla  # SciPy in each function: loading this module needs none

    M = _matrix("M", M)
    if M.ndim != 2 or M.shape[0] != M.shape[1] or M.shape[0] == 0:
        raise LCPError(f"`M` has shape {M.shape}: expected a square (n, n) mass matrix")
    n = M.shape[0]
    if not np.allclose(M, M.T, rtol=1e-10, atol=1e-12 * np.abs(M).max()):
        raise LCPError("`M` is not symmetric: pass the symmetric mass matrix")
    try:
        chol = sla.cho_factor(M)
    except sla.LinAlgError:
        raise LCPError(
            "`M` is not positive definite: every generalised coordinate "
            "needs inertia; remove massless coordinates first"
        ) from None
    W_N = _matrix("W_N", W_N)
    W_N = W_N.reshape(n, 1) if W_N.ndim == 1 and W_N.size == n else W_N
    if W_N.ndim != 2 or W_N.shape[0] != n or W_N.shape[1] == 0:
        raise LCPError(
            f"`W_N` has shape {W_N.shape}: expected ({n}, k_N) with k_N ≥ 1, "
            f"one column per normal contact (n = {n} from `M`)"
        )
    if W_T is None:
        W_T = np.zeros((n, 0))
    W_T = _matrix("W_T", W_T)
    W_T = W_T.reshape(n, 1) if W_T.ndim == 1 and W_T.size == n else W_T
    if W_T.ndim != 2 or W_T.shape[0] != n:
        raise LCPError(
            f"`W_T` has shape {W_T.shape}: expected ({n}, k_T), one column "
            "per sticking tangential direction (k_T may be 0)"
        )
    u = _matrix("u_minus", u_minus, (n,))
    eps = (
        np.broadcast_to(np.asarray(eps_p, dtype=float), (W_N.shape[1],)).copy()
        if np.ndim(eps_p) == 0
        else _matrix("eps_p", eps_p, (W_N.shape[1],))
    )
    if not (np.all(np.isfinite(eps)) and np.all((eps >= 0.0) & (eps <= 1.0))):
        raise LCPError(f"`eps_p` = {eps_p!r}: Poisson's coefficient must lie in [0, 1]")
    return chol, M, W_N, W_T, u, eps


def _delassus(chol, W_N, W_T):
    """G matrices of Eq 4 and the condensed normal matrix of Eqs 6 and 11."""
    import scipy.linalg as sla

    MiN = sla.cho_solve(chol, W_N)
    MiT = sla.cho_solve(chol, W_T)
    G_NN, G_NT, G_TT = W_N.T @ MiN, W_N.T @ MiT, W_T.T @ MiT  # paper 000, Eq 4
    if W_T.shape[1]:
        try:
            cT = sla.cho_factor(G_TT)
        except sla.LinAlgError:
            raise LCPError(
                "`W_T` has linearly dependent columns (G_TT singular): merge "
                "them into one resultant direction, as paper 000 Eq 13 does "
                "for two corners of a block"
            ) from None
        K = sla.cho_solve(cT, G_NT.T)  # G_TT⁻¹ G_TN
        A = G_NN - G_NT @ K  # paper 000, Eqs 6, 11
    else:
        cT, K, A = None, np.zeros((0, W_N.shape[1])), G_NN
    return MiN, MiT, G_NT, cT, K, 0.5 * (A + A.T)


def _snap(q: np.ndarray, vtol: float) -> np.ndarray:
    """Round-off in contact velocities (|ġ| ≤ vtol) to exact zeros before an LCP."""
    return np.where(np.abs(q) <= vtol, 0.0, q)


def _solve(A: np.ndarray, q: np.ndarray, vtol: float) -> tuple[np.ndarray, str]:
    """Solve the impact LCP by Lemke; on failure, as the equivalent NNLS problem.

    A is symmetric positive semidefinite and q lies in its range, so the LCP is
    the optimality condition of min ½zᵀAz + qᵀz over z ≥ 0 = min ‖Bz + c‖² with
    A = BᵀB, q = Bᵀc. Lemke can end on a false ray when many redundant contacts
    make A rank-deficient to round-off; Lawson–Hanson NNLS does not.
    """
    q = _snap(q, vtol)
    try:
        return lemke(A, q).z, "lemke"
    except LCPError as err:
        lam, V = np.linalg.eigh(A)
        keep = lam > 1e-12 * max(lam.max(), 1e-300)
        B = np.sqrt(lam[keep])[:, None] * V[:, keep].T
        c = (V[:, keep].T @ q) / np.sqrt(lam[keep])
        import scipy.optimize as so

        z = so.nnls(B, -c, maxiter=50 * q.size + 100)[0]
        w = A @ z + q
        if w.min() < -1e3 * vtol or np.abs(w * z).max() > 1e3 * vtol * max(z.max(), 1e-300):
            raise err
        return z, "nnls"


def _state(gdot: np.ndarray, tol: float) -> tuple[str, ...]:
    return tuple("closed" if g <= tol else "separating" for g in gdot)


def poisson_impact(M, W_N, W_T, u_minus, eps_p, *, tol: float = 1e-9) -> PoissonImpact:
    """Resolve an impact with Poisson's law and sticking contacts (paper 000, Eqs 1–12).

    Parameters
    ----------
    M : array_like, shape (n, n)
        Symmetric positive definite mass matrix at the impact configuration.
    W_N : array_like, shape (n, k_N)
        Normal directions, one column per closed contact (ġ_N = W_Nᵀ u).
    W_T : array_like, shape (n, k_T), or None
        Sticking tangential directions with independent columns (k_T may be 0).
    u_minus : array_like, shape (n,)
        Pre-impact generalised velocity.
    eps_p : float or array_like, shape (k_N,)
        Poisson's coefficient of restitution ε_P ∈ [0, 1] (Λ_N⁺ = ε_P Λ_N⁰).
    tol : float
        A contact counts as closed when ``ġ_N ≤ tol · max |(ġ_N⁻, ġ_T⁻)|``.

    Returns
    -------
    PoissonImpact

    Raises
    ------
    LCPError
        M not symmetric positive definite, inconsistent sizes, ε_P outside
        [0, 1], dependent tangential directions, or an LCP without solution.
    """
    import scipy.linalg as sla

    chol, M, W_N, W_T, u, eps = _validate(M, W_N, W_T, u_minus, eps_p)
    MiN, MiT, G_NT, cT, K, A = _delassus(chol, W_N, W_T)
    gN_m, gT_m = W_N.T @ u, W_T.T @ u
    scale = max(np.abs(gN_m).max(), np.abs(gT_m).max(initial=0.0), 1e-300)
    vtol = tol * scale
    # compression: ġ_N⁰ = A Λ_N⁰ + ġ_N⁻ (− G_NT G_TT⁻¹ ġ_T⁻ if the contact slips)
    q0 = gN_m - (G_NT @ sla.cho_solve(cT, gT_m) if cT is not None else 0.0)
    lam0, how0 = _solve(A, q0, vtol)  # paper 000, Eqs 6–7
    lamT0 = -(K @ lam0) - (sla.cho_solve(cT, gT_m) if cT is not None else 0.0)  # Eq 5
    u0 = u + MiN @ lam0 + MiT @ lamT0  # paper 000, Eq 2
    gN_0 = W_N.T @ u0
    # expansion: ġ_N⁺ = A Λ_NP + A ε Λ_N⁰ + ġ_N⁰
    elam0 = eps * lam0
    lamNP, how1 = _solve(A, A @ elam0 + gN_0, vtol)  # paper 000, Eqs 11–12
    lam_plus = lamNP + elam0
    lamT_plus = -(K @ lam_plus)  # paper 000, Eq 10
    u_plus = u0 + MiN @ lam_plus + MiT @ lamT_plus  # paper 000, Eq 8
    gN_p = W_N.T @ u_plus
    s0, s1 = _state(gN_0, vtol), _state(gN_p, vtol)
    loss = 0.5 * (u @ M @ u - u_plus @ M @ u_plus)
    return PoissonImpact(
        u_minus=u,
        u_compression=u0,
        u_plus=u_plus,
        impulse_compression=lam0,
        impulse_expansion=lam_plus,
        impulse_np=lamNP,
        tangential_impulse_compression=lamT0,
        tangential_impulse_expansion=lamT_plus,
        gN_minus=gN_m,
        gN_compression=gN_0,
        gN_plus=gN_p,
        states=tuple(zip(s0, s1)),
        energy_loss=float(loss),
        eps_p=eps,
        solver=(how0, how1),
    )
