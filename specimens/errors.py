"""The error raised for a specimen that cannot be used as written."""

__all__ = ["SpecimenError"]


class SpecimenError(ValueError):
    """A specimen file or mapping is invalid.

    The message names the file, the field (as a dotted TOML path), the value
    found and how to fix it.
    """
