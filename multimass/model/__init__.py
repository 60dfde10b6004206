"""The structural model: what a rocking structure is and the equations it obeys.

Structures built from specimens (condensed stiffness, Rayleigh damping, geometry), the
kinematics and energies, the equations of motion of each phase and their closed forms.
Imports only `multimass.specimens`, `multimass.impact_models` and the shared contract.
"""
