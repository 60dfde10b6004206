"""
Describe your structure: specimen files and what the validator refuses
======================================================================

A specimen is a TOML file with the unit in every key. Start from a bundled one, change
what differs in your structure, and load it; a value outside a plausible range is refused
with the likely slip and its fix, before anything is computed.
"""

# %%
# What a specimen file holds
# --------------------------
from pathlib import Path
from tempfile import mkdtemp

import matplotlib.pyplot as plt

import multimass
from multimass import modal, specimens

print(specimens.available())
spec = specimens.load("S1")
print(type(spec).__name__, spec.name, "-", spec.description)
print("heights (m):", spec.heights, "| masses (kg):", spec.masses)
print(f"E_s = {spec.E_s:.3g} Pa, I_s = {spec.I_s:.4g} m^4, K_rot = {spec.K_rot:.3g} N m/rad")

# %%
# The file itself (``specimens/data/S1.toml`` in the repository):
text = Path(specimens.__file__).with_name("data").joinpath("S1.toml").read_text()
print(text[:1500])

# %%
# Your own column
# ---------------
# Copy a file and change it. Here the section's second moment is halved:
own = Path(mkdtemp()) / "my_column.toml"
own.write_text(text.replace("second_moment_m4 = 183.3e-8", "second_moment_m4 = 91.65e-8"))
mine = multimass.column(own)
print("my column, uplifted f1 (Hz):", modal.analyse(mine).rocking.freq_hz[0].round(2))

# %%
# What the validator refuses, and why
# -----------------------------------
# A modulus typed in GPa, a section in cm⁴, a negative mass: each is one clear error that
# names the field, the value and the fix (`multimass.InputError`, a ``ValueError``).
slips = {
    "modulus in GPa": ("youngs_modulus_Pa = 200e9", "youngs_modulus_Pa = 200"),
    "section in cm^4": ("second_moment_m4 = 183.3e-8", "second_moment_m4 = 183.3"),
}
for what, (good, bad) in slips.items():
    wrong = Path(mkdtemp()) / "wrong.toml"
    wrong.write_text(text.replace(good, bad))
    try:
        multimass.column(wrong)
    except ValueError as err:
        print(f"{what}: {err}\n")

# %%
# The structure built from the file knows its geometry (paper 001, Table 1):
s1 = multimass.column("S1")
print(f"J_p = {s1.J_p:.1f} kg m², H_cg = {s1.H_cg:.3f} m, p_l = {s1.p_l:.3f} rad/s")

fig, ax = plt.subplots(figsize=(4, 4))
ax.barh(spec.heights, spec.masses, height=0.08)
ax.set(xlabel="mass (kg)", ylabel="height (m)", title="S1's lumped masses")
fig.tight_layout()
