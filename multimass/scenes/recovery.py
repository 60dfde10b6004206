"""Total accelerations at a column's own nodes from a (reduced) model's time history.

A reduced model (`multimass.scenes.reduce`) has other nodes than the column it
stands for, so its recorded accelerations ``a1..an`` are not the column's.
`node_accelerations` re-evaluates the equations of motion on every recorded
row (`multimass.model.eom.state_accelerations`) to get θ̈ and the reduced ü', maps
the elastic part back to the column's nodes with the recovery matrix R
(u ≈ R u', ü ≈ R ü') and applies paper 001's Eq 7 at the column's heights
(`multimass.model.eom.total_accelerations`). For the full column (R = I) this
reproduces the simulation's own ``a1..aN``; for the rigid equivalent (R
empty) it gives the rigid-body acceleration of a point at each node's height.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..model.eom import state_accelerations, total_accelerations
from .reduce import Reduced

__all__ = ["node_accelerations"]


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
    H = reduced.original.H[idx]
    return total_accelerations(st, phase, U @ Rk.T, theta, Udd @ Rk.T, thdd, thd, ag, H=H)
