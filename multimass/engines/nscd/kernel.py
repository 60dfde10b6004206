"""The compiled Moreau–Jean time loop (paper 002, Eqs 21–44).

One call runs every step: the free velocity (Eqs 21, 24), the configuration
q̄ at the end of the step under free flight, vertex–beam contact detection
(Eqs 59–63), local frames and Q (Eqs 45–58), the contact impulses
(Eqs 35–44, Gauss–Seidel) and the update (Eqs 22, 25, 34). Diagnostics are
accumulated on the fly: energy increase per step, Gauss–Seidel iterations,
sliding, half-cycle peaks, impacts and the last step at which the block moved.
Nothing is allocated inside the loop. `run_kernel` runs the compiled steps in
chunks (`run_steps`), carrying the state between calls, so that a long run can
report its progress; chunking does not change a single bit of the result.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numba
import numpy as np
from numba import njit

from .contact import beam_q, block_q, delassus_block, gauss_seidel
from .geometry import closest_point, contact_frame


def _drop_stale_cache() -> None:
    """Delete numba's cached nscd kernels when any compiled source or numba changed.

    numba keys a cached function on its own file only, so an edit of
    contact.py or geometry.py would leave run_kernel's cache stale.
    """
    here = Path(__file__).resolve().parent
    try:
        src = b"".join((here / f).read_bytes() for f in ("geometry.py", "contact.py", "kernel.py"))
        stamp = hashlib.sha256(src + numba.__version__.encode()).hexdigest()
        cache = here / "__pycache__"
        mark = cache / "nscd_kernel.stamp"
        if mark.is_file() and mark.read_text() == stamp:
            return
        for f in list(cache.glob("*.nbi")) + list(cache.glob("*.nbc")):
            f.unlink(missing_ok=True)
        cache.mkdir(exist_ok=True)
        mark.write_text(stamp)
    except OSError:  # read-only install or a concurrent process: numba recompiles if needed
        pass


_drop_stale_cache()

__all__ = [
    "run_kernel",
    "run_steps",
    "start_state",
    "STATUS",
    "STAT_NAMES",
    "SERIES",
    "TRACK_NAMES",
]

#: status codes returned by the kernel
STATUS = {0: "completed", 1: "overturned", 2: "fell_off_beam", 3: "failed"}
#: columns of the recorded series
SERIES = ("t", "phi", "phi_dot", "X", "Y", "v_mid", "energy", "n_contacts")
#: entries of the statistics vector
STAT_NAMES = (
    "max_gs_iterations",
    "n_gs_cap_hits",
    "n_multi_contact_steps",
    "n_slip_steps",
    "max_slip_speed",
    "max_energy_increase",
    "max_penetration",
    "last_moving_step",
    "n_contact_steps",
    "energy_scale",
    "max_gs_residual",
)
(I_GS, I_CAP, I_MULTI, I_SLIP, I_SLIPV, I_DE, I_PEN, I_MOVE, I_CONTACT, I_ESCALE, I_GSRES) = range(
    11
)
#: scalars carried from one call of `run_steps` to the next
TRACK_NAMES = ("energy", "sign", "peak", "t_peak", "n_peaks", "n_impacts", "last_row")
T_ENERGY, T_SIGN, T_PEAK, T_TPEAK, T_NPEAKS, T_NIMP, T_ROW = range(7)


@njit(cache=True)
def _spmv_add(csr, x, y, scale):
    """y += scale · A x for A = (indptr, indices, data) in CSR form."""
    ptr, idx, val = csr
    for i in range(ptr.size - 1):
        acc = 0.0
        for k in range(ptr[i], ptr[i + 1]):
            acc += val[k] * x[idx[k]]
        y[i] += scale * acc


@njit(cache=True)
def _quadratic(csr, x):
    """xᵀ A x for A in CSR form."""
    ptr, idx, val = csr
    out = 0.0
    for i in range(ptr.size - 1):
        acc = 0.0
        for k in range(ptr[i], ptr[i + 1]):
            acc += val[k] * x[idx[k]]
        out += x[i] * acc
    return out


@njit(cache=True)
def _energy(qk, vk, qe, ve, mass, inertia, Fk, Mc, Kc, pe):
    """Kinetic + elastic + gravitational energy (J)."""
    E = 0.5 * mass * (vk[0] ** 2 + vk[1] ** 2) + 0.5 * inertia * vk[2] ** 2
    E -= Fk[0] * qk[0] + Fk[1] * qk[1] + Fk[2] * qk[2]
    E += 0.5 * _quadratic(Mc, ve) + 0.5 * _quadratic(Kc, qe)
    for i in range(qe.size):
        E -= pe[i] * qe[i]
    return E


@njit(cache=True)
def _record(series, row, t, qk, vk, qe, i_mid, energy, nc):
    series[row, 0], series[row, 1], series[row, 2] = t, qk[2], vk[2]
    series[row, 3], series[row, 4] = qk[0], qk[1]
    series[row, 5] = qe[i_mid] if i_mid >= 0 else 0.0
    series[row, 6], series[row, 7] = energy, nc


@njit(cache=True)
def _free_step(
    qk, vk, qe, ve, vkf, vef, qkb, qeb, Fk, inv_m, inv_i, Ainv, Kc, Cc, pe, dt, theta, work
):
    """v̄ (paper 002, Eqs 21, 24, 34) and q̄ = q + Δt(θ v̄ + (1 − θ) v) (Eqs 22, 25)."""
    for k in range(3):
        vkf[k] = vk[k] + dt * Fk[k] * (inv_m if k < 2 else inv_i)  # Eq 21
        qkb[k] = qk[k] + dt * (theta * vkf[k] + (1.0 - theta) * vk[k])
    n = qe.size
    r, x = work[0], work[1]
    for i in range(n):
        r[i] = pe[i]
        x[i] = qe[i] + dt * theta * ve[i]
    _spmv_add(Kc, x, r, -1.0)  # −K(Δtθ q̇ + q) − C q̇ + p   (Eq 24)
    _spmv_add(Cc, ve, r, -1.0)
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += Ainv[i, j] * r[j]
        vef[i] = ve[i] + dt * acc
        qeb[i] = qe[i] + dt * (theta * vef[i] + (1.0 - theta) * ve[i])


@njit(cache=True)
def _beam_top(qeb, edof, Le):
    """An upper bound of v(x) on the span: max nodal v + Le · max |ϑ| / 4 + margin."""
    vmax, tmax = 0.0, 0.0
    for e in range(edof.shape[0]):
        for a in (1, 4):
            if edof[e, a] >= 0:
                vmax = max(vmax, qeb[edof[e, a]])
        for a in (2, 5):
            if edof[e, a] >= 0:
                tmax = max(tmax, abs(qeb[edof[e, a]]))
    return vmax + 0.25 * Le * tmax + 1e-9


@njit(cache=True)
def _detect(
    qkb,
    qeb,
    vk,
    ve,
    vkf,
    vef,
    verts,
    edof,
    x_nodes,
    Le,
    L,
    e_rest,
    Qk,
    Qe,
    el,
    ids,
    Ubar,
    Un_minus,
    N,
):
    """Active contacts at q̄ (gap ≤ 0, paper 002, Eq 35) with Q (Eqs 50, 55) and Ū = Q v̄ (Eq 42).

    Returns the number of contacts and the largest overlap.
    """
    c, s = math.cos(qkb[2]), math.sin(qkb[2])
    top = _beam_top(qeb, edof, Le)
    nc, pen = 0, 0.0
    for j in range(4):
        rx = c * verts[j, 0] - s * verts[j, 1]
        ry = s * verts[j, 0] + c * verts[j, 1]
        dx, dy = qkb[0] + rx, qkb[1] + ry
        if dx < 0.0 or dx > L or dy > top:
            continue
        e, sb = closest_point(qeb, edof, x_nodes, Le, dx, dy)
        cpsi, spsi, gap = contact_frame(N, qeb, edof, x_nodes, Le, e, sb, dx, dy)
        if gap > 0.0:
            continue
        pen = max(pen, -gap)
        block_q(Qk[nc], cpsi, spsi, rx, ry)
        beam_q(Qe[nc], cpsi, spsi, N)
        el[nc], ids[nc] = e, j
        un_m, un_f, ut_f = 0.0, 0.0, 0.0  # U⁻ = Q v_i, Ū = Q v̄
        for k in range(3):
            un_m += Qk[nc, 0, k] * vk[k]
            un_f += Qk[nc, 0, k] * vkf[k]
            ut_f += Qk[nc, 1, k] * vkf[k]
        for a in range(6):
            ia = edof[e, a]
            if ia >= 0:
                un_m -= Qe[nc, 0, a] * ve[ia]
                un_f -= Qe[nc, 0, a] * vef[ia]
                ut_f -= Qe[nc, 1, a] * vef[ia]
        Un_minus[nc] = un_m
        Ubar[nc, 0] = un_f + e_rest * min(un_m, 0.0)  # Newton: U_n + e U_n⁻ ≥ 0
        Ubar[nc, 1] = ut_f
        nc += 1
    return nc, pen


@njit(cache=True)
def _apply_impulses(nc, P, Qk, Qe, el, edof, vkf, vef, inv_m, inv_i, Ainv):
    """v_{i+1} = v̄ + B Qᵀ P (paper 002, Eq 34), in place on (vkf, vef)."""
    n = vef.size
    for h in range(nc):
        for k in range(3):
            vkf[k] += (inv_m if k < 2 else inv_i) * (Qk[h, 0, k] * P[h, 0] + Qk[h, 1, k] * P[h, 1])
        for a in range(6):
            ia = edof[el[h], a]
            if ia < 0:
                continue
            fa = -(Qe[h, 0, a] * P[h, 0] + Qe[h, 1, a] * P[h, 1])
            for i in range(n):
                vef[i] += Ainv[i, ia] * fa


@njit(cache=True)
def _slip_speed(nc, P, sliding, Qk, Qe, el, edof, vkf, vef):
    """Largest |U_t| after the step among loaded sliding contacts (−1 if none slides)."""
    worst = -1.0
    for h in range(nc):
        if not (sliding[h] and P[h, 0] > 0.0):
            continue
        ut = 0.0
        for k in range(3):
            ut += Qk[h, 1, k] * vkf[k]
        for a in range(6):
            ia = edof[el[h], a]
            if ia >= 0:
                ut -= Qe[h, 1, a] * vef[ia]
        worst = max(worst, abs(ut))
    return worst


@njit(cache=True)
def _solve_contacts(
    nc,
    ids,
    was_active,
    now_active,
    P,
    P_prev,
    W,
    Qk,
    Qe,
    el,
    Ubar,
    sliding,
    edof,
    Ainv,
    inv_m,
    inv_i,
    vkf,
    vef,
    mu,
    gs_tol,
    gs_max_iter,
    p_scale,
    stats,
):
    """Impulses of the active contacts (Eqs 41–44) and v_{i+1} = v̄ + B Qᵀ P (Eq 34)."""
    for h in range(nc):
        if was_active[ids[h]]:  # warm start
            P[h, 0], P[h, 1] = P_prev[ids[h], 0], P_prev[ids[h], 1]
        else:
            P[h, 0], P[h, 1] = 0.0, 0.0
        for j in range(nc):
            delassus_block(
                W[h, j], Qk[h], Qe[h], el[h], Qk[j], Qe[j], el[j], inv_m, inv_i, Ainv, edof
            )
    iters, ok, residual = gauss_seidel(W, Ubar, P, sliding, nc, mu, gs_tol, gs_max_iter, p_scale)
    stats[I_GS] = max(stats[I_GS], iters)
    if not ok:
        stats[I_CAP] += 1
        stats[I_GSRES] = max(stats[I_GSRES], residual)
    _apply_impulses(nc, P, Qk, Qe, el, edof, vkf, vef, inv_m, inv_i, Ainv)
    slip = _slip_speed(nc, P, sliding, Qk, Qe, el, edof, vkf, vef)
    if slip >= 0.0:
        stats[I_SLIP] += 1
        stats[I_SLIPV] = max(stats[I_SLIPV], slip)
    for h in range(nc):
        P_prev[ids[h], 0], P_prev[ids[h], 1] = P[h, 0], P[h, 1]
        now_active[ids[h]] = P[h, 0] > 0.0


@njit(cache=True)
def _advance(qk, vk, qe, ve, vkf, vef, dt, theta):
    """q_{i+1} = q_i + Δt(θ v_{i+1} + (1 − θ) v_i) (paper 002, Eqs 22, 25, 28); returns max |q_e|."""
    for k in range(3):
        qk[k] += dt * (theta * vkf[k] + (1.0 - theta) * vk[k])
        vk[k] = vkf[k]
    q_max = 0.0
    for i in range(qe.size):
        qe[i] += dt * (theta * vef[i] + (1.0 - theta) * ve[i])
        ve[i] = vef[i]
        q_max = max(q_max, abs(qe[i]))
    return q_max


@njit(cache=True)
def _half_cycle(phi, t, sign, peak, t_peak, cross_eps, peaks, n_peaks):
    """A sign change of φ (with hysteresis `cross_eps`) closes a half-cycle and logs its peak."""
    new_sign = 1 if phi > cross_eps else (-1 if phi < -cross_eps else sign)
    if new_sign != sign and sign != 0:
        if n_peaks < peaks.shape[0]:
            peaks[n_peaks, 0], peaks[n_peaks, 1] = t_peak, peak
            n_peaks += 1
        peak, t_peak = 0.0, t
    if abs(phi) > peak:
        peak, t_peak = abs(phi), t
    return new_sign, peak, t_peak, n_peaks


@njit(cache=True)
def start_state(
    qk, vk, qe, ve, mass, inertia, Fk, Mc, Kc, pe, L, i_mid, cross_eps, series, stats, track
):
    """Initial energy and energy scale, the first recorded row and the half-cycle state.

    Fills `series[0]`, `stats[I_ESCALE]` and `track` (see `TRACK_NAMES`) in place.
    """
    energy = _energy(qk, vk, qe, ve, mass, inertia, Fk, Mc, Kc, pe)
    stats[I_ESCALE] = abs(energy) + mass * abs(Fk[1]) * L
    _record(series, 0, 0.0, qk, vk, qe, i_mid, energy, 0)
    sign = 0
    if abs(qk[2]) > cross_eps:
        sign = 1 if qk[2] > 0 else -1
    track[T_ENERGY], track[T_SIGN], track[T_PEAK], track[T_TPEAK] = energy, sign, abs(qk[2]), 0.0
    track[T_NPEAKS], track[T_NIMP], track[T_ROW] = 0.0, 0.0, 0.0


@njit(cache=True)
def run_steps(
    first,
    last,
    qk,
    vk,
    qe,
    ve,
    was_active,
    P_prev,
    track,
    series,
    peaks,
    impacts,
    stats,
    mass,
    inertia,
    Fk,
    verts,
    Ainv,
    Mc,
    Kc,
    Cc,
    pe,
    edof,
    x_nodes,
    Le,
    L,
    dt,
    theta,
    mu,
    e_rest,
    gs_tol,
    gs_max_iter,
    stride,
    rest_angle,
    rest_rate,
    cross_eps,
    i_mid,
):
    """Moreau–Jean steps `first` … `last` (inclusive), continuing the state in place.

    The state that lives from one step to the next — (qk, vk, qe, ve), the
    contacts active at the end of the last step with their impulses (warm
    start), `track`, the logs and `stats` — is passed in and updated, so that
    running the steps in several calls gives the same numbers, bit for bit,
    as one call (tested). Everything else is scratch, rewritten every step.

    Returns
    -------
    status : int
        0 while running or at `last`, else the `STATUS` code that stopped the run.
    step : int
        The last step taken.
    """
    n = qe.size
    inv_m, inv_i = 1.0 / mass, 1.0 / inertia
    max_events = peaks.shape[0]
    p_scale = abs(Fk[1]) * dt  # weight impulse over one step
    v_impact = 10.0 * abs(Fk[1]) * inv_m * dt  # smallest approach speed logged as an impact
    Qk, Qe = np.zeros((4, 2, 3)), np.zeros((4, 2, 6))
    el, ids = np.zeros(4, dtype=np.int64), np.zeros(4, dtype=np.int64)
    Ubar, Un_minus, N = np.zeros((4, 2)), np.zeros(4), np.zeros(6)
    W, P = np.zeros((4, 4, 2, 2)), np.zeros((4, 2))
    sliding, now_active = np.zeros(4, dtype=np.bool_), np.zeros(4, dtype=np.bool_)
    vkf, vef, qkb, qeb = np.zeros(3), np.zeros(n), np.zeros(3), np.zeros(n)
    work = np.zeros((2, n))
    energy, sign, peak, t_peak = track[T_ENERGY], int(track[T_SIGN]), track[T_PEAK], track[T_TPEAK]
    n_peaks, n_imp, last_row = int(track[T_NPEAKS]), int(track[T_NIMP]), int(track[T_ROW])
    status, step = 0, first - 1
    for step in range(first, last + 1):
        t = step * dt
        _free_step(
            qk, vk, qe, ve, vkf, vef, qkb, qeb, Fk, inv_m, inv_i, Ainv, Kc, Cc, pe, dt, theta, work
        )
        nc, pen = _detect(
            qkb,
            qeb,
            vk,
            ve,
            vkf,
            vef,
            verts,
            edof,
            x_nodes,
            Le,
            L,
            e_rest,
            Qk,
            Qe,
            el,
            ids,
            Ubar,
            Un_minus,
            N,
        )
        stats[I_PEN] = max(stats[I_PEN], pen)
        now_active[:] = False
        if nc > 0:
            stats[I_CONTACT] += 1
            stats[I_MULTI] += 1 if nc > 1 else 0
            for h in range(nc):
                if not was_active[ids[h]] and Un_minus[h] < -v_impact and n_imp < max_events:
                    impacts[n_imp] = t
                    n_imp += 1
            _solve_contacts(
                nc,
                ids,
                was_active,
                now_active,
                P,
                P_prev,
                W,
                Qk,
                Qe,
                el,
                Ubar,
                sliding,
                edof,
                Ainv,
                inv_m,
                inv_i,
                vkf,
                vef,
                mu,
                gs_tol,
                gs_max_iter,
                p_scale,
                stats,
            )
        was_active[:] = now_active
        q_max = _advance(qk, vk, qe, ve, vkf, vef, dt, theta)
        e_new = _energy(qk, vk, qe, ve, mass, inertia, Fk, Mc, Kc, pe)
        stats[I_DE] = max(stats[I_DE], e_new - energy)
        energy = e_new
        # diverged: non-finite, or beam displacements beyond the span (linear theory long gone)
        if not (math.isfinite(energy) and math.isfinite(qk[0] + qk[1] + qk[2]) and q_max < L):
            status = 3
            break
        phi = qk[2]
        if abs(phi) > rest_angle or abs(vk[2]) > rest_rate:
            stats[I_MOVE] = step
        sign, peak, t_peak, n_peaks = _half_cycle(
            phi, t, sign, peak, t_peak, cross_eps, peaks, n_peaks
        )
        if step % stride == 0:
            last_row = step // stride
            _record(series, last_row, t, qk, vk, qe, i_mid, energy, nc)
        if abs(phi) > 0.5 * math.pi:
            status = 1
            break
        if nc == 0 and (qk[0] < -L or qk[0] > 2.0 * L or qk[1] < -L):
            status = 2
            break
    track[T_ENERGY], track[T_SIGN], track[T_PEAK], track[T_TPEAK] = energy, sign, peak, t_peak
    track[T_NPEAKS], track[T_NIMP], track[T_ROW] = n_peaks, n_imp, last_row
    return status, step


def run_kernel(
    qk0,
    vk0,
    qe0,
    ve0,
    mass,
    inertia,
    Fk,
    verts,
    Ainv,
    Mc,
    Kc,
    Cc,
    pe,
    edof,
    x_nodes,
    Le,
    L,
    dt,
    theta,
    mu,
    e_rest,
    gs_tol,
    gs_max_iter,
    n_steps,
    stride,
    rest_angle,
    rest_rate,
    cross_eps,
    i_mid,
    max_events,
    *,
    chunk=None,
    on_chunk=None,
):
    """Run `n_steps` Moreau–Jean steps from the given state (see module docstring).

    The compiled loop runs in calls of `chunk` steps (default: all at once);
    `on_chunk(step)` is called after each, e.g. to move a progress bar (and
    Python sees Ctrl-C between calls). The result does not depend on `chunk`.

    Returns
    -------
    status, last_step : int
    series : ndarray, shape (rows, len(SERIES))
    peaks : ndarray, shape (n_peaks, 2)
        (time, ``|φ|``) of each half-cycle, the release first.
    impacts : ndarray, shape (n_impacts,)
        Times of contact activations with U_n⁻ < −10 g Δt.
    stats : ndarray, shape (len(STAT_NAMES),)
    qk, vk, qe, ve : ndarray
        The final state.
    """
    qk, vk, qe, ve = (np.array(a, dtype=float) for a in (qk0, vk0, qe0, ve0))
    series = np.zeros((n_steps // stride + 1, len(SERIES)))
    peaks, impacts, stats = (
        np.zeros((max_events, 2)),
        np.zeros(max_events),
        np.zeros(len(STAT_NAMES)),
    )
    track = np.zeros(len(TRACK_NAMES))
    was_active, P_prev = np.zeros(4, dtype=np.bool_), np.zeros((4, 2))
    start_state(
        qk, vk, qe, ve, mass, inertia, Fk, Mc, Kc, pe, L, i_mid, cross_eps, series, stats, track
    )
    chunk = n_steps if chunk is None else max(1, int(chunk))
    status, step, first = 0, 0, 1
    while first <= n_steps and status == 0:
        last = min(first + chunk - 1, n_steps)
        status, step = run_steps(
            first,
            last,
            qk,
            vk,
            qe,
            ve,
            was_active,
            P_prev,
            track,
            series,
            peaks,
            impacts,
            stats,
            mass,
            inertia,
            Fk,
            verts,
            Ainv,
            Mc,
            Kc,
            Cc,
            pe,
            edof,
            x_nodes,
            Le,
            L,
            dt,
            theta,
            mu,
            e_rest,
            gs_tol,
            gs_max_iter,
            stride,
            rest_angle,
            rest_rate,
            cross_eps,
            i_mid,
        )
        if on_chunk is not None:
            on_chunk(step)
        first = last + 1
    n_peaks, peak = int(track[T_NPEAKS]), track[T_PEAK]
    if peak > cross_eps and n_peaks < max_events:  # close the last half-cycle
        peaks[n_peaks] = track[T_TPEAK], peak
        n_peaks += 1
    n_imp, last_row = int(track[T_NIMP]), int(track[T_ROW])
    return (
        status,
        step,
        series[: last_row + 1],
        peaks[:n_peaks],
        impacts[:n_imp],
        stats,
        qk,
        vk,
        qe,
        ve,
    )
