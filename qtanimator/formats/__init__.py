"""Readers and writers, one module per format. Every reader raises :class:`FormatError`."""

from qtanimator.formats.errors import FormatError

__all__ = ["FormatError"]
