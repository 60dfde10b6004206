"""
From test traces back to the model
==================================

A researcher has released a column on a shake table and holds θ and four accelerations
at 200 Hz. This example takes such a trace back to the model: the operational modes in
the trace, each impact's coefficient of restitution, a calibration of the restitution
means and the Dirac-delta force's C_p, and the comparison of the calibrated model with
the test.

The "test" here is the bundled synthetic trace ``examples/data/S1_DD2_synthetic.csv``
(made by ``multimass synthetic``): S1 released from 0.11 rad with DD2, each impact's r
drawn about the corner means (0.93, 0.87; σ_r = 0.025), recorded as a data logger would —
anti-alias filter, 200 Hz, noise 2 % of each channel's peak, sensor bias, a 12 ms clock
offset. The truth is in a sidecar JSON that no tool reads; we read it only at the end, to
check the answers.
"""

# %%
# The trace
# ---------
import json
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import multimass
from multimass import identify

data = Path(multimass.__file__).resolve().parents[1] / "examples" / "data"
trace = multimass.read_trace(data / "S1_DD2_synthetic.csv")
s1 = multimass.column("S1")
print(f"{trace.specimen}: channels {trace.names}, {trace.duration:.1f} s")

# %%
# Operational modes
# -----------------
# Each rocking half-cycle and full-contact stretch, the rigid-body part of the
# accelerations removed, fitted with damped sinusoids, against the model's modes (paper
# 001, Fig 5). Modes above the logger's 80 Hz passband are listed as not identifiable.
modes = identify.operational_modes(trace, s1)
modes.to_pandas()[["phase", "mode", "freq_hz", "model_freq_hz", "damping", "model_damping", "mac"]]

# %%
# Restitution, impact by impact
# -----------------------------
# Two estimates per impact: the paper's energy estimate (paper 001, Section 4.3), from the
# peaks before and after, and a model-based fit of each impact's r with DD2 on the
# compiled path, so that the simulated θ and accelerations match the trace.
est = identify.restitution(trace, s1, impact="DD2", progress=False)
corner = est.table()
# the impacts between half-cycles above 0.01 rad (the paper's rule) are estimated
impacts = est.summary()["impacts"][: len(corner["empirical"])]
print(
    f"{len(impacts)} impacts estimated; r_er = {corner['mean_right']}, "
    f"r_el = {corner['mean_left']}, σ_r = {corner['sigma']}"
)

# %%
# Calibration
# -----------
# Least squares of the restitution means and C_p against θ and the four accelerometers,
# from a start 20 % off; status ``converged``, ``misfit`` or ``ill-posed``.
cal = identify.calibrate(
    trace,
    s1,
    impact="DD2",
    fit=("r_er", "r_el", "cp"),
    start={"r_er": 0.744, "r_el": 0.696, "cp": 2100.0},
    progress=False,
)
print(cal.summary()["status"], "-", cal.summary()["message"])
cal.to_pandas()[["value", "std", "start"]]

# %%
# Against the truth
# -----------------
# Only now is the sidecar read: the r drawn for each impact, and the nominal values.
truth = json.loads((data / "S1_DD2_synthetic.truth.json").read_text())
drawn = np.array([i["r"] for i in truth["impacts"]])
t_drawn = np.array([i["t"] for i in truth["impacts"]])
t_est = np.array([i["t"] for i in impacts])
match = [int(np.argmin(np.abs(t_drawn - t))) for t in t_est]
r_model = np.array([i["r"] for i in impacts])
r_energy = np.array([i["r_energy"] for i in impacts])
print("largest |model-based r - drawn r|:", f"{np.abs(r_model - drawn[match]).max():.4f}")
print("largest |energy estimate - drawn r|:", f"{np.abs(r_energy - drawn[match]).max():.4f}")
print("calibrated C_p:", f"{cal.values['cp']:.1f}", "(truth 1750)")

fig, ax = plt.subplots(figsize=(7, 3.2))
k = np.arange(1, len(impacts) + 1)
ax.plot(k, drawn[match], "ks", mfc="none", ms=9, label="truth (drawn)")
ax.plot(k, r_model, "o", label="model-based fit (DD2)")
ax.plot(k, r_energy, "x", label="energy estimate (paper 001)")
ax.set(xlabel="impact", ylabel="r", title="Restitution of each impact")
ax.legend(fontsize=8)
fig.tight_layout()

# %%
# The calibrated model against the test
# -------------------------------------
# `multimass.compare_trace` gives RMS and peak errors per channel and the peak-time shift.
calibrated = multimass.from_specimen(cal.specimen())
r = multimass.simulate(calibrated, trace.free_release(), impact="DD2", t_end=6, backend="compiled")
metrics = multimass.compare_trace(trace, r, calibrated, t_offset=0.012)
print({name: round(m.rms_error, 5) for name, m in metrics.items()})
fig, ax = plt.subplots(figsize=(7, 3))
theta = next(v for k, v in trace.channels.items() if k.startswith("theta"))
ax.plot(trace.time, theta, "k.", ms=2, label="test (synthetic)")
ax.plot(r.series["t"] + 0.012, r.series["theta"], label="calibrated DD2")
ax.set(xlabel="t (s)", ylabel="θ (rad)", xlim=(0, 6))
ax.legend()
fig.tight_layout()
