"""
Rocking spectra of a column
===========================

How far does S1 rock as a pulse's frequency changes, or as a record is scaled up?
A rocking spectrum runs one simulation per point (paper 001, Figs 10 and 12); with DD5's
random restitution each point is repeated and summarised by its mean and spread.
"""

# %%
# Over a cosine pulse's frequency
# -------------------------------
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import multimass
from multimass.sweeps.spectra import pulse_spectrum, record_spectrum

s1 = multimass.column("S1")
spec = pulse_spectrum(
    s1,
    "cosine",
    omega=np.linspace(5, 30, 11),
    amp=0.4 * multimass.G,
    impact="DD2",
    executor="serial",
    progress=False,
)
table = spec.table
print(table[["omega", "theta_max", "status", "n_impacts"]].round(4).to_string(index=False))
fig, ax = plt.subplots(figsize=(6, 3))
ax.plot(table["omega"], table["theta_max"], "o-")
ax.set(xlabel="ω (rad/s)", ylabel="θ_max (rad)", title="S1, cosine pulse 0.4 g, DD2")
fig.tight_layout()

# %%
# Over a record's scale, random restitution (DD5)
# -----------------------------------------------
# The first 15 s of El Centro 1940 NS; three repeats per scale, each with its own seeded
# restitution draws. The result is the same whatever executor runs it.
data = Path(multimass.__file__).resolve().parents[1] / "examples" / "data"
record = multimass.read_record(data / "elcentro_1940_NS_15s.dat", units="g")
spec = record_spectrum(
    s1, record, scale=np.linspace(0.4, 1.6, 5), repeats=3, executor="serial", progress=False
)
stats = spec.stats("scale")
print(stats.round(4).to_string())
t = spec.table
fig, ax = plt.subplots(figsize=(6, 3))
done = t[t.status == "completed"]
ax.plot(done["scale"], done["theta_max"], "o", alpha=0.5, label="runs")
ax.plot(stats["scale"], stats["mean"], "-", label="mean of completed runs")
ax.set(xlabel="scale A_sc", ylabel="θ_max (rad)", title="S1, El Centro, DD5")
ax.legend()
fig.tight_layout()
