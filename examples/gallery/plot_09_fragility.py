"""
Suites and fragility: how likely is it to overturn?
===================================================

A suite runs one structure under many motions — recorded accelerograms scaled to
intensity levels and/or Mavroeidis–Papageorgiou near-fault pulses — with Monte-Carlo
restitution draws, and fits lognormal fragility curves by maximum likelihood (Baker
2015). This small suite (160 runs of block B6M under M&P pulses) runs in seconds; the
same code scales to the 6000-run suite of the benchmarks page.
"""

# %%
# The suite
# ---------
import matplotlib.pyplot as plt
import numpy as np
from scipy.stats import norm

import multimass
from multimass.fragility import fit_lognormal
from multimass.suites import (
    Distribution,
    PulseSet,
    Suite,
    fragility_curves,
    im_efficiency,
    run_suite,
)

suite = Suite(
    name="B6M, M&P pulses",
    structure=multimass.rigid_block("B6M"),
    pulses=PulseSet(omega_p_over_p=(1.5, 3.0)),
    measure="amp_over_g_tan_alpha",
    levels=[1.0, 1.4, 2.0, 2.8, 4.0],
    draws=16,
    restitution="modified",
    k=Distribution("normal", 0.82, 0.05),
    seed=1,
)
runs = run_suite(suite, executor="serial", progress=False).runs
print(len(runs), "runs;", runs.columns.tolist()[:12], "...")
runs.groupby(["omega_p_over_p", "level"])["overturned"].mean().unstack()

# %%
# Fragility curves
# ----------------
# θ (the median) and β (the dispersion) per damage state: overturning, and θ_max/α ≥ 0.5
# and 0.8, here in PGV.
curves = fragility_curves(runs, im="pgv")
curves

# %%
# Which intensity measure predicts overturning best? The smallest β wins: for pulses,
# the velocity (PGV) rather than the acceleration.
im_efficiency(runs)

# %%
# The lognormal fit by hand
# -------------------------
# `multimass.fragility.fit_lognormal` takes levels, trials and exceedances; its status
# says when the data cannot define a curve (no or only exceedances, separated data).
over = runs.groupby("pgv")["overturned"].agg(["size", "sum"])
fit = fit_lognormal(over.index.to_numpy(), over["size"].to_numpy(), over["sum"].to_numpy())
print(f"θ = {fit.theta:.3f} m/s, β = {fit.beta:.3f}, status {fit.status}")
x = np.linspace(over.index.min() * 0.5, over.index.max() * 1.5, 200)
fig, ax = plt.subplots(figsize=(6, 3.2))
ax.plot(over.index, over["sum"] / over["size"], "o", label="share overturned")
ax.plot(x, norm.cdf(np.log(x / fit.theta) / fit.beta), label="lognormal fit")
ax.set(xlabel="PGV (m/s)", ylabel="P(overturn)", title="B6M under M&P pulses")
ax.legend()
fig.tight_layout()
