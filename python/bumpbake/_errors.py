"""The exceptions bumpbake raises. Messages are one line in plain words and name Python keywords."""

from __future__ import annotations

__all__ = ["Error", "InputError", "OutputError", "UsageError"]


class Error(Exception):
    """Base class of every error bumpbake raises."""


class InputError(Error):
    """A file or array that cannot be used: unreadable, malformed or unsupported.

    What the command line reports with exit code 2 for an input. Nothing was written.
    """


class UsageError(Error, ValueError):
    """An option asks for something impossible: an unknown keyword, a value out of range,
    options that contradict each other."""


class OutputError(Error, OSError):
    """An output could not be written. Nothing partial is left behind."""
