"""The error raised by the modal package."""

from multimass.errors import InputError

__all__ = ["ModalError"]


class ModalError(InputError):
    """A linear system or shape set cannot be analysed as given."""
