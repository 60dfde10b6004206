"""
How it vibrates: uplifted modes, compound shapes, MAC and FRFs
==============================================================

Once a column uplifts it vibrates about its corner: the base rotation couples to the
elastic modes, and the frequencies change (paper 001, Section 3). This example compares
the two phases of S1, shows the compound shapes of the uplifted phase, measures how alike
the shapes are (MAC) and draws the frequency response from the ground to the sensors.
"""

# %%
# Frequencies of both phases
# --------------------------
import matplotlib.pyplot as plt
import numpy as np

import multimass
from multimass import modal

s1 = multimass.column("S1")
res = modal.analyse(s1)
for phase in (res.full_contact, res.rocking):
    print(
        f"{phase.phase:13s} f (Hz): {phase.freq_hz[:3].round(2)}  ζ: {phase.damping[:3].round(4)}"
    )
print("rocking eigenvalues ±p_l (rad/s):", np.real(res.rocking_eigenvalues).round(4))

# %%
# Shapes: full contact against the compound (uplifted) modes
# ----------------------------------------------------------
# A compound shape is the elastic shape plus the rigid rotation about the pivot; the
# first one of S1 changes sign near 1.3 m (paper 001, Section 4.2).
heights = res.heights
full = np.real(res.full_contact_shapes())
compound = np.real(res.compound_shapes())
fig, axes = plt.subplots(1, 3, figsize=(8, 3.6), sharey=True)
for k, ax in enumerate(axes):
    ax.plot(full[:, k] / np.abs(full[:, k]).max(), heights, "o-", label="full contact")
    ax.plot(compound[:, k] / np.abs(compound[:, k]).max(), heights, "s--", label="uplifted")
    ax.axvline(0, color="0.7", lw=0.8)
    ax.set(title=f"mode {k + 1}", xlabel="normalised shape")
axes[0].set_ylabel("height (m)")
axes[0].legend(loc="lower left", fontsize=8)
fig.tight_layout()

# %%
# MAC
# ---
# `multimass.modal.mac` compares two sets of shapes (1: the same shape, 0: orthogonal).
# The first uplifted mode is far from the first full-contact mode; the higher modes hardly
# change. Pass measured shapes to compare with a test (``multimass modal --measured``).
print(modal.mac(full[:, :3], compound[:, :3]).round(2))

# %%
# Frequency response
# ------------------
# `multimass.modal.frf` gives the linearised system's response from ground acceleration
# to the sensors' accelerations, for either phase.
f = np.linspace(1, 60, 600)
fig, ax = plt.subplots(figsize=(7, 3.2))
for phase, style in (("full_contact", "-"), ("rocking", "--")):
    h = modal.frf(s1, f, phase=phase, sensors=[5])  # node 5: accelerometer A4
    ax.semilogy(f, np.abs(h[0]), style, label=f"{phase.replace('_', ' ')}, top sensor")
ax.set(xlabel="f (Hz)", ylabel="|H|", title="S1: ground → top accelerometer")
ax.legend()
fig.tight_layout()
