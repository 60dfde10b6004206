"""Errors raised by the engine for bad input and for failed solutions."""

__all__ = ["InputError", "SolverError"]


class InputError(ValueError):
    """An argument to a public function is invalid.

    The message names the argument, the value and the fix.
    """


class SolverError(RuntimeError):
    """A numerical solution failed; the message carries the solver's status."""
