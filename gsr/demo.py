"""The symbolic end-to-end demo: LIBERO task -> scene graph -> plan -> every step checked -> goal verified.

``gsr demo --symbolic`` runs it: the whole symbolic pipeline on a real LIBERO task file, with no simulator
or vision extras. ``make demo`` runs the physical demo instead (the benchmarks layer's: PyBullet
execution and perception), which falls back to suggesting this one when those extras are missing.
"""

from __future__ import annotations

from pathlib import Path

import typer

from gsr.errors import GSRError
from gsr.graph_text import to_prompt_text
from gsr.libero import libero_task
from gsr.pddl.bddl import load_bddl
from gsr.plan import plan
from gsr.resources import data_dir, load_builtin_domain
from gsr.transition import apply_step
from gsr.validate import validate_plan

DEFAULT_TASK = (
    "libero_10/KITCHEN_SCENE4_put_the_black_bowl_in_the_bottom_drawer_of_the_cabinet_and_close_it.bddl"
)


def default_task_path() -> Path:
    """The demo's LIBERO task, shipped with the project (``data/libero``, MIT; see ``data/README.md``)."""
    return data_dir() / "libero" / DEFAULT_TASK


def run_demo(task: Path | None = None, planner: str = "lazy-ff") -> int:
    """Run the demo on ``task`` (a BDDL file); returns the process exit code (0 only when the goal is verified)."""
    path = task or default_task_path()
    if not path.is_file():
        raise GSRError(f"{path}: task file not found (pass --task FILE)")
    domain = load_builtin_domain()
    bddl = load_bddl(path)
    graph, problem = libero_task(bddl, domain)
    typer.echo(f"task:        {path.name}")
    typer.echo(f"instruction: {bddl.language or '(none)'}")
    typer.echo(f"scene graph: {len(graph.nodes)} nodes, {len(graph.edges)} edges")
    typer.echo("  " + to_prompt_text(graph, terse=True).replace("\n", "\n  "))

    result = plan(domain, problem, planner=planner, timeout=60.0)
    typer.echo(
        f"\nplanner:     {result.planner}: {result.status} in {result.time * 1000:.1f} ms ({result.message})"
    )
    if not result.solved or result.plan is None:
        typer.echo("no plan: the goal cannot be reached", err=True)
        return 1

    typer.echo(f"plan:        {len(result.plan)} steps, each checked against the tabletop domain")
    for i, step in enumerate(result.plan, 1):
        graph = apply_step(graph, step, domain)  # raises StepRejected with the diagnosis if invalid
        typer.echo(f"  {i:2d}. {step}  ok")
    report = validate_plan(domain, problem, result.plan)
    typer.echo(f"\nvalidator:   {report.message}")
    if not report.valid:
        return 1
    typer.echo("goal verified on the final scene graph")
    return 0
