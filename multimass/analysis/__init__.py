"""What is made of results and traces: intensity measures, fragility, trace metrics, figures.

Intensity measures of records (PGA, PGV, Sa), fragility curves fitted by maximum
likelihood, the distance between a simulation and a recorded trace, and the figures of
time histories. Imports the model, the inputs and the result contract; never an engine.
"""
