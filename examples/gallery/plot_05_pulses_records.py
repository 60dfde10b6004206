"""
How it rocks: pulses and recorded ground motions
================================================

Ground motions are callables ü_g(t) with a duration: single sine and cosine waves and the
cosine pulse of paper 001 (Section 4.4), Ricker wavelets, the Mavroeidis–Papageorgiou
near-fault pulse, and records read from PEER ``.AT2`` files or two columns with explicit
units. Pulses take keyword arguments only, so an amplitude is never taken for a frequency.
"""

# %%
# A pulse and a record
# --------------------
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import multimass
from multimass import CosinePulse, MPPulse, Ricker, simulate

pulses = {
    "cosine pulse": CosinePulse(amplitude=0.4 * multimass.G, omega=15.0),
    "Ricker": Ricker(amplitude=0.4 * multimass.G, omega=15.0),
    "M&P (velocity 0.2 m/s, 2.4 Hz)": MPPulse(amplitude=0.2, fp=2.4, gamma=2.5, nu=0.5),
}
t = np.linspace(0, 1.5, 1500)
fig, ax = plt.subplots(figsize=(7, 2.8))
for name, p in pulses.items():
    ax.plot(t, [p.acceleration(x) / multimass.G for x in t], label=name)
ax.set(xlabel="t (s)", ylabel="ü_g (g)")
ax.legend()
fig.tight_layout()

# %%
# The bundled 15 s of El Centro 1940 NS (two columns, in g), scaled by 1.1 as in paper 001:
data = Path(multimass.__file__).resolve().parents[1] / "examples" / "data"
record = multimass.read_record(data / "elcentro_1940_NS_15s.dat", units="g", scale=1.1)
print(record.describe())

# %%
# S1 under both, on the compiled path
# -----------------------------------
s1 = multimass.column("S1")
fig, axes = plt.subplots(2, 1, figsize=(7, 5))
for ax, (name, ex, t_end) in zip(
    axes,
    [
        ("cosine pulse 0.4 g, ω = 15 rad/s", pulses["cosine pulse"], 4.0),
        ("El Centro × 1.1", record, 8.0),
    ],
    strict=True,
):
    r = simulate(s1, ex, impact="DD2", t_end=t_end, backend="compiled")
    print(f"{name}: {r.status}, θ_max = {r.theta_max:.4f} rad, {r.n_impacts} impacts")
    ax.plot(r.series["t"], r.series["theta"])
    ax.set(title=name, ylabel="θ (rad)")
axes[-1].set_xlabel("t (s)")
fig.tight_layout()
