"""What drives a run or comes from a test: excitations, pulses, records, traces, units.

Ground motions as callables (free release, waves, pulses, recorded motions), the readers
of records and test traces, their units and the checks of sampled signals.
Imports only the model (`multimass.model`), the specimens and the shared contract.
"""
