"""Model no more than a scene needs: scenes, adequacy criteria and automatic model choice.

A `Scene` says what stands where (a column, a block, a block on a beam), what shakes it,
what the user wants to know and how exactly. `choose` walks the model ladder from the
cheapest model (a rigid body) to the richest (the N-node column, or the block on an FE
beam) and picks the cheapest one that is adequate by documented a-priori criteria
(`multimass.scenes.criteria`); with ``verify=True`` it runs the next richer model and
measures the difference.

>>> import multimass
>>> from multimass.scenes import Question, Scene, Tolerance
>>> scene = Scene("S2 modes", "S2", multimass.FreeRelease(0.05),
...               Question("uplifted_frequencies", n_modes=1), Tolerance(0.01))
>>> multimass.choose(scene).model
'sdof'
"""

from .choice import Choice, Comparison, choose, estimate_cost, format_answer
from .criteria import Verdict, assess
from .recovery import node_accelerations
from .reduce import Reduced, modal_reduction, rigid_equivalent, sdof
from .rungs import Rung, RungAnswer, ladder
from .scene import QUESTIONS, Question, Scene, Tolerance

__all__ = [
    "Choice",
    "Comparison",
    "QUESTIONS",
    "Question",
    "Reduced",
    "Rung",
    "RungAnswer",
    "Scene",
    "Tolerance",
    "Verdict",
    "assess",
    "choose",
    "format_answer",
    "estimate_cost",
    "ladder",
    "modal_reduction",
    "node_accelerations",
    "rigid_equivalent",
    "sdof",
]
