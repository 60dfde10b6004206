"""The package's one error family: every error a user can cause or meet is a `MultimassError`.

``MultimassError`` derives from ``ValueError`` (the command line prints any ValueError as one
line, exit status 2, and a script can catch the whole family at once):

* `InputError` — an argument, a file or a value is invalid (its subclasses:
  `multimass.specimens.SpecimenError` for specimen files, `multimass.modal.ModalError`
  for the modal analysis);
* `SolverError` — a numerical solution failed (also a ``RuntimeError``; its subclass
  `multimass.impact_models.LCPError` for a linear complementarity problem without a
  solution); the sweeps' `JobError` and `ExecutorError` are solver errors of a sweep.

This module imports nothing, so the bottom layers (specimens, impact_models) may share it.
"""

__all__ = ["MultimassError", "InputError", "SolverError"]


class MultimassError(ValueError):
    """Base of every error the package raises on purpose."""


class InputError(MultimassError):
    """An argument to a public function is invalid.

    The message names the argument, the value and the fix.
    """


class SolverError(MultimassError, RuntimeError):
    """A numerical solution failed; the message carries the solver's status."""
