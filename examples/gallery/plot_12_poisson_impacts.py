"""
Impacts with Poisson's law: paper 000's blocks and oscillator
=============================================================

Paper 000 resolves every impact as a linear complementarity problem (LCP) with Poisson's
coefficient ε_P: bouncing, flight and pure rocking all come out of the same equations.

* Fig 4: free rocking of a stocky (H/b = 0.7) and a slender (H/b = 7) block, 2b = 1 m,
  released from φ0/α = 1/3, with ε_P = 0, 0.5 and 1.
* Fig 5: the slender block under a single sine pulse a_g/g = 0.45, ω_g/p = 5.75, with
  ε_P = 0, overlaid on Housner's classical model (paper 004, Eqs 1–2, 9): they agree.
* Section 4: the flexible rocking oscillator under a Ricker pulse for three ε_P
  (illustrative properties: paper 000 takes its specimens from its ref. [23], which is
  not reproduced).
"""

import math
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from multimass import Ricker, SineWave
from multimass.flexible_oscillator import FlexibleOscillator, simulate_oscillator
from multimass.poisson_block import PoissonBlock, housner_theta, simulate_block

EPS = (0.0, 0.5, 1.0)
STYLE = {
    0.0: dict(color="k", lw=1.4),
    0.5: dict(color="tab:blue", lw=1.1),
    1.0: dict(color="tab:red", lw=0.9, ls="--"),
}


def _save(fig, name: str):
    """Lay the figure out; the gallery shows it (``OUT=DIR python ...`` also saves it)."""
    fig.tight_layout()
    if os.environ.get("OUT"):
        fig.savefig(Path(os.environ["OUT"]) / name, dpi=110)
    return fig


def sample(t, x, grid):
    """Values at the grid times (post-event value where an event falls on a grid time)."""
    idx = np.searchsorted(t, grid, side="right") - 1
    return x[idx]


def figure_4():
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), sharey=True)
    for ax, hb, name in zip(axes, (0.7, 7.0), ("stocky, H/b = 0.7", "slender, H/b = 7")):
        block = PoissonBlock.from_slenderness(hb, width=1.0)
        t_end = 4.0 if hb < 1 else 10.0
        for eps in EPS:
            r = simulate_block(block, eps, t_end, phi0=block.alpha / 3, dt_out=0.002)
            ax.plot(r.t, r.phi / block.alpha, label=f"ε_P = {eps:g}", **STYLE[eps])
            kinds = [e.kind for e in r.events]
            flights = np.mean(r.phase == "flight")
            print(
                f"Fig 4 {name:18s} ε_P={eps:3.1f}: {kinds.count('impact'):4d} impacts, "
                f"flight {100 * flights:4.1f}% of samples, final phase {r.phase[-1]}, "
                f"ledger error {np.abs(r.raw.ledger_error).max() / r.raw.energy[0]:.1e} E0"
            )
        ax.set_title(name)
        ax.set_xlabel("t (s)")
        ax.axhline(0.0, color="0.7", lw=0.5)
    axes[0].set_ylabel("φ / α")
    axes[0].legend(loc="upper right", fontsize=8)
    fig.suptitle(
        "Paper 000, Fig 4: free rocking from φ0/α = 1/3, Poisson impacts (LCP)", fontsize=10
    )
    return _save(fig, "fig4_free_rocking.png")


def figure_5():
    block = PoissonBlock.from_slenderness(7.0, width=1.0)
    a_g, w_g = 0.45 * block.g, 5.75 * block.p
    ag = SineWave(amplitude=a_g, omega=w_g)
    t_end = 15.0
    r = simulate_block(block, 0.0, t_end, ag=ag, dt_out=0.002)
    grid = np.arange(0.0, t_end, 0.002)
    t_up = math.asin(block.g * math.tan(block.alpha) / a_g) / w_g  # ag = g tan α
    theta_h = housner_theta(block, ag, t_up, 0.0, grid, side=-int(np.sign(ag(t_up))))
    phi_lcp = sample(r.t, r.phi, grid)
    diff = phi_lcp + theta_h  # φ = −θ
    print(
        f"Fig 5: max |φ_LCP − φ_Housner| / α = {np.abs(diff).max() / block.alpha:.2e} over "
        f"{t_end:g} s; peak |φ|/α = {np.abs(phi_lcp).max() / block.alpha:.3f}; "
        f"{len(r.raw.impacts)} impacts; phases {sorted(str(p) for p in set(r.phase))}"
    )
    fig, (ax, ax2) = plt.subplots(
        2, 1, figsize=(9, 5), sharex=True, gridspec_kw=dict(height_ratios=[3, 1])
    )
    ax.plot(
        grid,
        -theta_h / block.alpha,
        color="tab:orange",
        lw=3.0,
        alpha=0.6,
        label="Housner, classical impact (η_H)",
    )
    ax.plot(grid, phi_lcp / block.alpha, color="k", lw=1.0, label="LCP, Poisson ε_P = 0")
    ax.plot(grid, [ag(t) / block.g for t in grid], color="0.6", lw=0.8, ls=":", label="a_g(t)/g")
    ax.set_ylabel("φ / α")
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title("Paper 000, Fig 5: H/b = 7, sine pulse a_g/g = 0.45, ω_g/p = 5.75", fontsize=10)
    ax2.plot(grid, diff / block.alpha, color="k", lw=0.8)
    ax2.set_ylabel("difference / α")
    ax2.set_xlabel("t (s)")
    ax2.ticklabel_format(axis="y", style="sci", scilimits=(0, 0))
    return _save(fig, "fig5_sine_pulse_vs_housner.png")


def figure_oscillator():
    osc = FlexibleOscillator.from_frequency(
        2.0, m=1000.0, m_c=200.0, m_b=300.0, h=2.0, b=0.3, zeta=0.02
    )
    ag = Ricker(amplitude=0.25 * osc.g, omega=2 * math.pi * 1.0)
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
    for eps in EPS:
        r = simulate_oscillator(osc, eps, 6.0, ag=ag, dt_out=0.002)
        ax.plot(r.t, r.phi / osc.alpha, label=f"ε_P = {eps:g}", **STYLE[eps])
        ax2.plot(r.t, 1e3 * r.u, **STYLE[eps])
        err = np.abs(r.raw.ledger_error).max() / np.abs(r.raw.ground_work).max()
        print(
            f"Oscillator ε_P={eps:3.1f}: {len(r.raw.impacts)} impacts, "
            f"flight {100 * np.mean(r.phase == 'flight'):4.1f}% of samples, "
            f"ledger error {err:.1e} × max ground work"
        )
    ax.set_ylabel("φ / α")
    ax.legend(fontsize=8)
    ax.set_title(
        "Flexible rocking oscillator (paper 000, Sec 4), Ricker pulse "
        "a_g/g = 0.25, ω_g = 2π rad/s — illustrative properties",
        fontsize=9,
    )
    ax2.set_ylabel("u (mm)")
    ax2.set_xlabel("t (s)")
    return _save(fig, "oscillator_ricker.png")


# %%
# Fig 4: free rocking, bouncing and flight
# ----------------------------------------
figure_4()

# %%
# Fig 5: the LCP with ε_P = 0 follows Housner's model
# ---------------------------------------------------
figure_5()

# %%
# The flexible rocking oscillator (Section 4)
# -------------------------------------------
figure_oscillator()
