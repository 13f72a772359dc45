"""Errors GSR raises for bad input: each carries a one-line, user-facing message."""

from __future__ import annotations


class GSRError(Exception):
    """Base class: bad input or an impossible request, with a clear message (CLI exit 1)."""


class ParseError(GSRError):
    """A syntax or semantic error in a PDDL/BDDL/step text, located by file, line and column."""

    def __init__(
        self,
        message: str,
        *,
        source: str = "<string>",
        line: int | None = None,
        column: int | None = None,
        expected: tuple[str, ...] = (),
    ) -> None:
        self.message = message
        self.source = source
        self.line = line
        self.column = column
        self.expected = expected
        where = source if line is None else f"{source}:{line}:{column or 0}"
        text = f"{where}: {message}"
        if expected:
            text += f" (expected {', '.join(expected)})"
        super().__init__(text)
