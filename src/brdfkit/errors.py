"""Exceptions raised at brdfkit's public boundary.

Every error states the constraint, the value received and, where there is one,
the fix. They derive from :class:`ValueError` so callers that already catch
``ValueError`` keep working; the command line catches :class:`BrdfkitError`
and prints its message on one line.
"""


class BrdfkitError(ValueError):
    """Base class of brdfkit's user-facing errors."""


class ParameterError(BrdfkitError):
    """A parameter is unknown, out of its bounds, or of the wrong shape."""


class UnknownModelError(BrdfkitError):
    """A model name is not in the registry."""


class DataFileError(BrdfkitError):
    """A data file is malformed: names the file, the field, expected vs found."""
