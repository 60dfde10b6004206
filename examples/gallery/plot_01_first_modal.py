"""
Getting started: the first modal report and the first time history
===================================================================

Load the bundled column S1 of paper 001 (a four-storey steel frame on a rocking base),
ask for its modes in full contact and once it has uplifted, then release it from
0.11 rad and watch it rock.
"""

# %%
# The column and its modes
# ------------------------
# `multimass.column` takes a bundled specimen's name or the path of your own TOML file.
# `multimass.modal.analyse` solves the Foss state-space eigenproblem (paper 001, Eq 24)
# for both phases: full contact and rocking on a corner.
import matplotlib.pyplot as plt

import multimass
from multimass import FreeRelease, modal, simulate

s1 = multimass.column("S1")
res = modal.analyse(s1)
print("full contact (Hz):", res.full_contact.freq_hz[:3].round(2))
print("uplifted (Hz):    ", res.rocking.freq_hz[:3].round(2))
print("uplifted damping: ", res.rocking.damping[:2].round(4))
print("published (Hz):    7.6, 41.4 full contact; 20.7, 46.9 uplifted (paper 001)")

# %%
# The table of modes as pandas:
res.rocking.to_pandas().head(3)

# %%
# The first time history
# ----------------------
# Released from 0.11 rad with the Dirac-delta impact model DD2 of paper 001 Table 2, on
# the compiled path. The result says how far to trust it (``status``), lists every
# event and keeps the series as a DataFrame.
r = simulate(s1, FreeRelease(0.11), impact="DD2", t_end=4, backend="compiled")
print(r.status, "| impacts:", r.n_impacts, "| first peaks (rad):", r.peaks[:4].round(4))

fig, ax = plt.subplots(figsize=(7, 3))
ax.plot(r.series["t"], r.series["theta"])
ax.set(xlabel="t (s)", ylabel="θ (rad)", title="S1 released from 0.11 rad, DD2")
fig.tight_layout()
