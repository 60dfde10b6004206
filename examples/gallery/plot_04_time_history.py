"""
How it rocks: impact models and the energy ledger
=================================================

What happens at impact decides how a column rocks. The toolkit has three families:
the classical impact (CIM: an instantaneous jump of the velocities, paper 001 Eqs 9–12),
the Dirac-delta force (DD1–DD5: a short Gaussian force near θ = 0 that lets the column
vibrate through the impact, paper 001 Eqs 14–17) and Poisson's law solved as an LCP
(paper 000), where every contact's impulse follows from the structure's own inertia.

Which one to use:

* **CIM** when only θ matters and the structure is stiff: cheapest, no vibration at impact.
* **DD2** (corner means of restitution, Table 2) when accelerations matter: the Gaussian
  force excites the elastic modes at impact as the tests show (paper 001, Section 4.3).
* **DD5** (random restitution per impact) for spectra and fragility: the scatter of a
  real test.
* **LCP** with ``eps_p`` (Poisson's coefficient) when no restitution coefficient is known:
  the impact follows from the structure (η_H exactly for a rigid block).
"""

# %%
# Three models, one release
# -------------------------
import matplotlib.pyplot as plt

import multimass
from multimass import FreeRelease, simulate

s1 = multimass.column("S1")
runs = {
    "CIM": simulate(s1, FreeRelease(0.11), impact="CIM", t_end=3, backend="compiled"),
    "DD2": simulate(s1, FreeRelease(0.11), impact="DD2", t_end=3, backend="compiled"),
    "LCP, ε_P = 0": simulate(s1, FreeRelease(0.11), impact="LCP", t_end=3, eps_p=0.0),
}
fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
for name, r in runs.items():
    print(f"{name:13s} {r.status:9s} first peaks after release (rad): {r.peaks[1:4].round(4)}")
    ax1.plot(r.series["t"], r.series["theta"], label=name)
    ax2.plot(r.series["t"], r.series["a5"] / multimass.G, label=name, lw=0.8)
ax1.set(ylabel="θ (rad)")
ax2.set(xlabel="t (s)", ylabel="top acceleration (g)")
ax1.legend(ncols=3, fontsize=8)
fig.tight_layout()

# %%
# The events of a run
# -------------------
# Uplift, the Dirac-delta force's activation and release, impacts, full contact and
# overturning, with their times and states:
runs["DD2"].events_frame().head(8)

# %%
# The energy ledger
# -----------------
# Every run books kinetic, gravitational and elastic energy, the work of damping, of the
# impacts and of the ground. Their balance closes to the integrator's tolerance; a run
# whose balance is off by more than ``energy_tol`` (1e-3 of its scale) is reported
# ``inaccurate``, with the reason in ``warnings``.
r = runs["DD2"]
ledger = r.ledger
fig, ax = plt.subplots(figsize=(7, 3.2))
for col in ("kinetic", "gravitational", "elastic", "damping", "impact"):
    ax.plot(ledger["t"], ledger[col], label=col)
ax.set(xlabel="t (s)", ylabel="energy (J)", title="S1, DD2: where the energy goes")
ax.legend(fontsize=8, ncols=3)
fig.tight_layout()
print("largest balance error / energy scale:", f"{r.energy_balance_error:.1e}")
