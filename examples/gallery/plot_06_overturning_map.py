"""
Rigid blocks: will it overturn? Overturning maps under pulses
=============================================================

A museum plinth or a cabinet is a rigid block. Under a single sine pulse of frequency
ω_p and amplitude a0, does it overturn? An overturning map answers for a whole grid of
pulses at once (paper 004, Figs 4–9), with the restitution of Housner (η_H) or the
modified one of paper 004 (η_M, Eq 10).
"""

# %%
# Housner's and the modified restitution of block B6M
# ----------------------------------------------------
import matplotlib.pyplot as plt
import numpy as np

import multimass
from multimass.impact_models import housner_eta, modified_eta
from multimass.sweeps.maps import overturning_map

b6m = multimass.rigid_block("B6M")
print(f"B6M: α = {b6m.alpha_cg:.4f} rad, p = {b6m.p:.3f} rad/s")
print(
    f"η_H = {housner_eta(b6m.alpha_cg):.3f}, η_M = {modified_eta(b6m.alpha_cg, 0.8241):.3f} (k = 0.8241)"
)

# %%
# A 24 × 24 map, both restitutions
# --------------------------------
# ω/p from 0.5 to 10, a0/(α g) from 0.25 to 8; the compiled batched kernel runs every
# cell (``executor="serial"`` here: a gallery example runs in one process).
omega_p = np.linspace(0.5, 10, 24)
amp = np.linspace(0.25, 8, 24)
maps = {
    r: overturning_map(
        "B6M", "sine", omega_p=omega_p, amp=amp, restitution=r, executor="serial", progress=False
    )
    for r in ("modified", "housner")
}
fig, axes = plt.subplots(1, 2, figsize=(9, 3.8), sharey=True)
for ax, (name, m) in zip(axes, maps.items(), strict=True):
    ax.pcolormesh(omega_p, amp, m.overturned(), cmap="Greys", vmin=0, vmax=1.6, shading="nearest")
    bound = m.min_overturn_amp()
    ax.plot(
        omega_p,
        [np.nan if b is None else b for b in bound],
        "r-",
        lw=1,
        label="first overturning amplitude",
    )
    ax.set(title=f"η {name}: {100 * m.overturn_fraction():.1f} % overturn", xlabel="ω_p / p")
    print(
        f"{name}: {m.n_simulations()} simulations in {m.wall_time_s:.2f} s, "
        f"overturned share {100 * m.overturn_fraction():.1f} %"
    )
axes[0].set_ylabel("a0 / (α g)")
axes[0].legend(fontsize=8, loc="upper left")
fig.suptitle("B6M under a sine pulse (dark: overturns)")
fig.tight_layout()

# %%
# Three engines, one answer
# -------------------------
# A single cell by the solve_ivp path, the compiled path and paper 004's Newmark scheme:
from multimass import SineWave, simulate

g_tan = multimass.G * np.tan(b6m.alpha_cg)
pulse = SineWave(amplitude=3.0 * g_tan, omega=4.0 * b6m.p)
for kw in ({"backend": "scipy"}, {"backend": "compiled"}, {"integrator": "newmark", "dt": 1e-4}):
    r = simulate(b6m, pulse, impact="CIM", t_end=6, restitution="modified", **kw)
    print(f"{kw}: {r.outcome} at t = {r.t[-1]:.4f} s")
