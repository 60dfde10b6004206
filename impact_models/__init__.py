"""What happens at impact: restitution formulas, classical and Dirac-delta impact
models, and impacts as a linear complementarity problem with Poisson's law."""

from .restitution import housner_eta, modified_eta, r_h

__all__ = ["housner_eta", "modified_eta", "r_h"]
