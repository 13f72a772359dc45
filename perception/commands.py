"""The perception layer's `gsr` commands (registered through the ``gsr.cli`` entry point group)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def register(app: typer.Typer) -> None:
    """Add ``gsr perceive`` to the ``gsr`` command."""

    @app.command("perceive")
    def perceive_cmd(
        rgb: Annotated[
            list[Path],
            typer.Option(help="RGB image (PNG/JPEG, or .npy HxWx3 uint8); repeat for more cameras."),
        ],
        depth: Annotated[
            list[Path] | None,
            typer.Option(help="Depth: .npy float metres, or 16-bit PNG millimetres; one per --rgb."),
        ] = None,
        camera: Annotated[
            list[Path] | None,
            typer.Option(help="Camera JSON (intrinsics + cam_to_world), docs/perception.md; one per --rgb."),
        ] = None,
        masks: Annotated[
            Path | None,
            typer.Option(
                help="Optional instance ids from an external segmenter (.npy int / PNG; negative = none). "
                "Without it the built-in detector segments and recognises (no simulator input)."
            ),
        ] = None,
        labels: Annotated[
            Path | None,
            typer.Option(help="With --masks: labels JSON, mask id -> {id, category, color, parent}."),
        ] = None,
        weights: Annotated[
            Path | None,
            typer.Option(
                help="Detector weights (gsr perceive-train --out DIR); default: the trained or geometry-only detector."
            ),
        ] = None,
        previous: Annotated[
            Path | None,
            typer.Option(
                help="An earlier graph of the same scene: ids are kept (tracking), hidden objects remembered."
            ),
        ] = None,
        out: Annotated[
            Path | None, typer.Option(help="Write the scene graph JSON here (default: stdout).")
        ] = None,
    ) -> None:
        """Perceive RGB-D frames (one or more cameras) into a scene graph JSON; masks are optional."""
        from gsr.errors import GSRError
        from gsr.io import write_text_atomic
        from gsr.scene_graph import SceneGraph

        depths, cameras = list(depth or []), list(camera or [])
        if masks is not None:
            from gsr.perception.pipeline import perceive_files

            if len(rgb) != 1 or len(depths) != 1 or len(cameras) != 1:
                raise GSRError("perceive: --masks takes exactly one --rgb, --depth and --camera")
            graph = perceive_files(rgb[0], depths[0], masks, cameras[0], labels, out)
        else:
            from gsr.perception.rgbd import perceive_view_files

            if labels is not None:
                raise GSRError("perceive: --labels needs --masks (they name the masks' ids)")
            prior = SceneGraph.load(previous) if previous is not None else None
            graph = perceive_view_files(rgb, depths, cameras, weights, prior)
            if out is not None:
                write_text_atomic(Path(out), graph.to_json() + "\n")
        if out is None:
            typer.echo(graph.to_json())
        else:
            typer.echo(f"wrote {out}: {len(graph.nodes)} nodes, {len(graph.edges)} edges", err=True)
