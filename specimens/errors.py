"""The error raised for a specimen that cannot be used as written."""

from multimass.errors import InputError

__all__ = ["SpecimenError"]


class SpecimenError(InputError):
    """A specimen file or mapping is invalid.

    The message names the file, the field (as a dotted TOML path), the value
    found and how to fix it.
    """
