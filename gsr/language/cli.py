"""``gsr ground``: print the goal an instruction grounds to (the typer wrapper lives in gsr/cli.py)."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from gsr.io import load_scene
from gsr.language.errors import GroundingError
from gsr.language.ground import ground
from gsr.pddl.writer import write_formula


def goal_payload(instruction: str, goal_text: str, scene: Path) -> dict[str, object]:
    """The JSON object ``gsr ground --json`` prints on success."""
    return {"instruction": instruction, "scene": str(scene), "goal": goal_text}


def ground_command(scene: Path, instruction: str, as_json: bool) -> int:
    """Ground ``instruction`` on the scene file; print the goal as PDDL (or JSON). Returns the exit code."""
    graph = load_scene(scene)  # GSRError (bad file) -> exit 1 via gsr.cli.main
    try:
        goal = ground(instruction, graph)
    except GroundingError as exc:
        if as_json:
            typer.echo(
                json.dumps(
                    {
                        "instruction": instruction,
                        "error": exc.message,
                        "unknown_words": list(exc.unknown_words),
                        "candidates": list(exc.candidates),
                        "suggestions": {w: list(c) for w, c in exc.suggestions.items()},
                    },
                    indent=2,
                )
            )
        typer.echo(f"error: {exc.message}", err=True)
        return 1
    text = write_formula(goal.formula)
    typer.echo(json.dumps(goal_payload(instruction, text, scene), indent=2) if as_json else text)
    return 0
