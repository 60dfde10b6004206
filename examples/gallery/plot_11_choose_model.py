"""
Which model does my question need?
==================================

A rigid block, a one-mode oscillator, a column with fewer modes, the full column, a block
on a finite-element beam: each answers some questions well enough and costs less than the
next. A *scene* states the structure, the excitation, the question (peak rotation, a peak
acceleration, uplifted frequencies, overturning) and the tolerance; `multimass.choose`
climbs the ladder from the cheapest rung and, with ``verify=True``, checks the chosen
rung against the next richer one.
"""

# %%
import matplotlib.pyplot as plt

import multimass
from multimass import CosinePulse
from multimass.scenes import Question, Scene, Tolerance, format_answer

pulse = CosinePulse(amplitude=0.4 * multimass.G, omega=15.0)
questions = {
    "peak rotation": (Question("peak_rotation"), Tolerance(0.05)),
    "peak acceleration at A2": (Question("peak_acceleration", sensor="A2"), Tolerance(0.10)),
}
choices = {}
for name, (question, tolerance) in questions.items():
    scene = Scene(f"S1 pulse: {name}", "S1", pulse, question, tolerance)
    c = multimass.choose(scene, verify=True)
    choices[name] = c
    print(f"{name}: {c.label} answers {format_answer(c.answer, c.unit)};")
    print(
        f"    against {c.verified_against}: difference {c.difference:.3g}, adequate: {c.adequate}"
    )

# %%
# The ladder it climbed and why each rung was taken or left, for the acceleration:
c = choices["peak acceleration at A2"]
print("ladder:", " → ".join(c.ladder))
print(c.reason)

# %%
# The chosen answer and the richer model's, side by side:
fig, axes = plt.subplots(1, 2, figsize=(7, 2.8))
for ax, (name, c) in zip(axes, choices.items(), strict=True):
    ax.bar([c.model, c.verified_against], [c.answer, c.verified_answer], color=["C0", "C1"])
    ax.set(title=name, ylabel=c.unit)
fig.tight_layout()
