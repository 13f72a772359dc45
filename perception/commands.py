"""The perception layer's `gsr` commands (registered through the ``gsr.cli`` entry point group)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def register(app: typer.Typer) -> None:
    """Add ``gsr perceive`` to the ``gsr`` command."""

    @app.command("perceive")
    def perceive_cmd(
        rgb: Annotated[Path, typer.Option(help="RGB image (PNG/JPEG, or .npy HxWx3 uint8).")],
        depth: Annotated[Path, typer.Option(help="Depth: .npy float metres, or 16-bit PNG millimetres.")],
        masks: Annotated[Path, typer.Option(help="Instance ids: .npy int array or PNG; negative = none.")],
        camera: Annotated[
            Path, typer.Option(help="Camera JSON (intrinsics + cam_to_world), docs/perception.md.")
        ],
        labels: Annotated[
            Path | None, typer.Option(help="Labels JSON: mask id -> {id, category, color, parent}.")
        ] = None,
        out: Annotated[
            Path | None, typer.Option(help="Write the scene graph JSON here (default: stdout).")
        ] = None,
    ) -> None:
        """Perceive one RGB-D frame with instance masks into a scene graph JSON."""
        from gsr.perception.pipeline import perceive_files

        graph = perceive_files(rgb, depth, masks, camera, labels, out)
        if out is None:
            typer.echo(graph.to_json())
        else:
            typer.echo(f"wrote {out}: {len(graph.nodes)} nodes, {len(graph.edges)} edges", err=True)
