"""Total accelerations at a column's own nodes from a (reduced) model's time history.

A reduced model (`multimass.scenes.reduce`) has other nodes than the column it
stands for, so its recorded accelerations ``a1..an`` are not the column's.
`node_accelerations` re-evaluates the equations of motion on every recorded
row to get θ̈ and the reduced ü', maps the elastic part back to the column's
nodes with the recovery matrix R (u ≈ R u', ü ≈ R ü') and applies paper 001
Eq 7 at the column's heights. For the full column (R = I) this reproduces the
simulation's own ``a1..aN``; for the rigid equivalent (R empty) it gives the
rigid-body acceleration of a point at each node's height.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .reduce import Reduced

__all__ = ["node_accelerations", "state_accelerations"]


def state_accelerations(st, phase: np.ndarray, U, theta, Ud, thd, ag, F):
    """ü (rows × n) and θ̈ (rows) of each recorded state (paper 001, Eqs 3–5).

    Vectorised over rows; `phase` is 0 (full contact, θ̈ = 0) or ±1.
    """
    n, m, H, B, g = st.n, st.m, st.H, st.B, st.g
    Udd = np.zeros_like(U)
    thdd = np.zeros_like(theta)
    fc = phase == 0
    if n and fc.any():  # paper 001, Eq 3
        Udd[fc] = -(Ud[fc] @ st.C.T + U[fc] @ st.K.T) / m - ag[fc, None]
    rk = ~fc
    if not rk.any():
        return Udd, thdd
    s, th, w = phase[rk].astype(float), theta[rk], thd[rk]
    u, ud, a, f = U[rk], Ud[rk], ag[rk], F[rk]
    c, sn = np.cos(th), np.sin(th)
    mu = u * m
    smu = mu.sum(axis=1)
    height = float(m @ H) + st.m0 * st.h0
    lever = s * B * st.m_t - smu
    arm = s[:, None] * B * m - mu
    bu = (
        -arm * (w**2)[:, None] - ud @ st.C.T - u @ st.K.T - m * (a * c - g * sn)[:, None]
    )  # paper 001, Eq 4
    bt = (
        2.0 * w * np.einsum("ij,ij->i", ud, arm)
        - 2.0 * B * f
        - a * (height * c + lever * sn)
        - g * (-height * sn + lever * c)
    )  # paper 001, Eq 5
    a_tt = st.J_p + np.einsum("ij,ij->i", u, mu) - 2.0 * s * B * smu
    thdd[rk] = (bt - bu @ H) / (a_tt - H @ (m * H))
    if n:
        Udd[rk] = bu / m - np.outer(thdd[rk], H)
    return Udd, thdd


def node_accelerations(reduced: Reduced, series, nodes) -> np.ndarray:
    """Total lateral accelerations (m/s²) at the original column's `nodes`.

    Parameters
    ----------
    reduced : Reduced
        The model that was simulated and its recovery matrix.
    series : pandas.DataFrame
        `Response.series` of that simulation (needs ``output_dt``).
    nodes : sequence of int
        1-based node numbers of the original column.

    Returns
    -------
    ndarray, shape (rows, len(nodes))
        a = ü + H θ̈ + (±B − u) θ̇² + ü_g cos θ − g sin θ (paper 001, Eq 7).
    """
    st, R = reduced.structure, reduced.recovery
    if series is None or len(series) == 0:
        raise InputError(
            "`series` is empty: simulate with `output_dt` set to record the "
            "time history the accelerations are computed from"
        )
    idx = np.asarray(nodes, dtype=int) - 1
    if idx.size == 0 or idx.min() < 0 or idx.max() >= R.shape[0]:
        raise InputError(f"`nodes` = {list(nodes)!r}: give node numbers in 1..{R.shape[0]}")
    n = st.n
    phase = series["phase"].to_numpy().astype(int)
    theta, thd = series["theta"].to_numpy(), series["thetadot"].to_numpy()
    ag, F = series["ag"].to_numpy(), series["F_i"].to_numpy()
    U = series[[f"u{i + 1}" for i in range(n)]].to_numpy() if n else np.zeros((phase.size, 0))
    Ud = series[[f"udot{i + 1}" for i in range(n)]].to_numpy() if n else np.zeros((phase.size, 0))
    Udd, thdd = state_accelerations(st, phase, U, theta, Ud, thd, ag, F)
    Rk = R[idx]
    u, udd = U @ Rk.T, Udd @ Rk.T
    Hk = reduced.original.H[idx]
    s = phase.astype(float)[:, None]
    rocking = (
        udd
        + np.outer(thdd, Hk)
        + (s * st.B - u) * (thd**2)[:, None]
        + (ag * np.cos(theta) - st.g * np.sin(theta))[:, None]
    )  # paper 001, Eq 7
    return np.where(phase[:, None] == 0, udd + ag[:, None], rocking)
