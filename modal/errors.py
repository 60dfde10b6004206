"""The error raised by the modal package."""

__all__ = ["ModalError"]


class ModalError(ValueError):
    """A linear system or shape set cannot be analysed as given."""
