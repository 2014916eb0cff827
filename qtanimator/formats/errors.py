"""The one exception every reader raises."""

from __future__ import annotations

import os


class FormatError(ValueError):
    """A file could not be read. Carries the file, line and column and a plain sentence.

    ``str(error)`` reads like ``wasp.skel, line 12, column 5: expected a number after
    'offset', found 'abc'.`` so the GUI and the command line can show it as it is.
    """

    def __init__(self, message: str, path: str | os.PathLike[str] | None = None,
                 line: int | None = None, column: int | None = None) -> None:
        self.message = message
        self.path = os.fspath(path) if path is not None else None
        self.line = line
        self.column = column
        super().__init__(self._render())

    def __reduce__(self) -> tuple[type[FormatError], tuple[str, str | None, int | None, int | None]]:
        # Keep path, line and column when the error crosses a process boundary (pickle).
        return (type(self), (self.message, self.path, self.line, self.column))

    def _render(self) -> str:
        where = []
        if self.path is not None:
            where.append(os.path.basename(self.path))
        if self.line is not None:
            where.append(f"line {self.line}")
        if self.column is not None:
            where.append(f"column {self.column}")
        return (", ".join(where) + ": " if where else "") + self.message
