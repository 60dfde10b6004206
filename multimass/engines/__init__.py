"""The engines that integrate a rocking structure through time.

The column's phase loop with its events and recorder, the rigid block and its Newmark
integrator, the paper-000 contact engine, the flexible oscillator, the Moreau–Jean
time stepper (`nscd`) and the compiled kernels (`fast`). Imports the model, the inputs,
the impact models and the shared contract; nothing of analysis, sweeps or the CLI.
"""
