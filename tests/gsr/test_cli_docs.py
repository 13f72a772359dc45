"""docs/cli.md is generated from the typer app: it must list every command and be up to date."""

from __future__ import annotations

from pathlib import Path

from gsr.cli_docs import cli_reference

DOC = Path(__file__).resolve().parents[2] / "docs" / "cli.md"


def test_cli_reference_is_up_to_date() -> None:
    assert DOC.read_text(encoding="utf-8") == cli_reference(), (
        "docs/cli.md is stale: run `python -m gsr.cli_docs > docs/cli.md`"
    )


def test_reference_covers_every_command() -> None:
    text = cli_reference()
    for command in (
        "gsr parse",
        "gsr validate",
        "gsr plan",
        "gsr check",
        "gsr solve",
        "gsr ground",
        "gsr serve",
        "gsr bench run",
        "gsr demo",
        "gsr schema scene-graph",
    ):
        assert f"### `{command}`" in text, command
