"""Figures of a modal analysis (headless: matplotlib's object API, no pyplot state)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from .analysis import ModalAnalysis

__all__ = ["plot_eigenvalues", "plot_shapes"]


def plot_eigenvalues(analysis: ModalAnalysis, path: str | Path) -> Path:
    """Damped eigenvalues of both phases on the complex plane (paper 001, Fig 4 left).

    Left: all eigenvalues; right: zoom on the rocking pair and the first two
    vibration modes.
    """
    fc, rk = analysis.full_contact.eigenvalues, analysis.rocking.eigenvalues
    fig = Figure(figsize=(11, 4.5), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax in axes:
        ax.scatter(fc.real, fc.imag, marker="o", facecolors="none", edgecolors="tab:blue",
                   label="full contact")
        ax.scatter(rk.real, rk.imag, marker="x", color="tab:red", label="rocking")
        ax.axhline(0, color="0.7", lw=0.6)
        ax.axvline(0, color="0.7", lw=0.6)
        ax.set_xlabel("Re Λ (rad/s)")
        ax.set_ylabel("Im Λ (rad/s)")
        ax.grid(alpha=0.3)
    axes[0].set_title(f"{analysis.structure.name}: all eigenvalues")
    n_zoom = min(2, analysis.rocking.omega.size)
    lim = 1.15 * max(analysis.rocking.omega[:n_zoom].max(), analysis.full_contact.omega[:n_zoom].max())
    re_lim = 1.3 * max(np.abs(analysis.rocking_eigenvalues).max(),
                       np.abs(analysis.rocking.vibration_eigenvalues[:n_zoom].real).max())
    axes[1].set_xlim(-re_lim, re_lim)
    axes[1].set_ylim(-lim, lim)
    axes[1].set_title("zoom: rocking pair and modes 1–2")
    p = analysis.structure.p_l
    axes[1].scatter([p, -p], [0, 0], marker="+", s=120, color="k", label="±p_l (Eq 6)")
    for k, lam in enumerate(analysis.rocking.vibration_eigenvalues[:n_zoom]):
        axes[1].annotate(f"u{k + 1}: {abs(lam) / (2 * np.pi):.1f} Hz", (lam.real, lam.imag),
                         textcoords="offset points", xytext=(6, 4), fontsize=8, color="tab:red")
    for k, lam in enumerate(analysis.full_contact.vibration_eigenvalues[:n_zoom]):
        axes[1].annotate(f"n{k + 1}: {abs(lam) / (2 * np.pi):.1f} Hz", (lam.real, lam.imag),
                         textcoords="offset points", xytext=(6, -10), fontsize=8, color="tab:blue")
    axes[1].legend(loc="lower left", fontsize=8)
    path = Path(path)
    fig.savefig(path, dpi=120)
    return path


def plot_shapes(analysis: ModalAnalysis, path: str | Path, n_modes: int = 3) -> Path:
    """Mode shapes over height (paper 001, Fig 4 right): full contact v_n,
    uplifted elastic part v_t and compound shape v_c = v_t + H v_r, and the
    rocking mode."""
    h = analysis.heights
    k = min(n_modes, analysis.rocking.omega.size, analysis.full_contact.omega.size)
    vn, vt, vc = (analysis.full_contact_shapes(), analysis.elastic_shapes(),
                  analysis.compound_shapes())
    fig = Figure(figsize=(3.0 * (k + 1), 4.8), layout="constrained")
    axes = fig.subplots(1, k + 1, sharey=True)
    for j in range(k):
        ax = axes[j]
        sign = np.sign(vn[:, j] @ vc[:, j]) or 1.0
        ax.plot(sign * vn[:, j], h, "o--", color="0.45", label="full contact v_n")
        ax.plot(sign * vt[:, j], h, "s-", color="tab:blue", lw=1, label="uplifted elastic v_t")
        ax.plot(sign * vc[:, j], h, "D-", color="tab:red", lw=2, label="uplifted compound v_c")
        ax.set_title(f"mode {j + 1}\n[{analysis.full_contact.freq_hz[j]:.1f}, "
                     f"{analysis.rocking.freq_hz[j]:.1f}] Hz", fontsize=10)
    rs = analysis.rocking_shape
    idx = np.asarray(analysis.shape_nodes) - 1
    rt, rc = rs[idx], rs[idx] + h * rs[-1]
    scale = np.linalg.norm(rc)
    ax = axes[k]
    ax.plot(rt / scale, h, "s-", color="tab:blue", lw=1, label="elastic part")
    ax.plot(rc / scale, h, "D-", color="tab:red", lw=2, label="compound")
    ax.set_title(f"rocking mode\nΛ = ±{analysis.rocking_eigenvalues[0]:.3f} rad/s", fontsize=10)
    for ax in axes:
        ax.axvline(0, color="0.7", lw=0.6)
        ax.set_xlabel("ordinate (normalised)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("height (m)")
    handles = axes[0].get_legend_handles_labels()[0]
    fig.legend(handles=handles, loc="outside lower center", ncol=3, fontsize=8)
    fig.suptitle(f"{analysis.structure.name}: mode shapes [f_full contact, f_uplifted]")
    path = Path(path)
    fig.savefig(path, dpi=120)
    return path
