"""What every layer's `gsr` commands share: the one-line error exit."""

from __future__ import annotations

import typer


def fail(message: str, code: int = 1) -> typer.Exit:
    """Print ``error: message`` on stderr and return the ``typer.Exit`` to raise (exit ``code``)."""
    typer.echo(f"error: {message}", err=True)
    return typer.Exit(code)
