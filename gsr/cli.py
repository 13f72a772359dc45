"""The `gsr` command line: a thin typer layer over the library.

Exit codes: 0 success, 1 bad input / invalid plan (with a one-line reason on stderr);
`gsr plan` adds 2 (proven unsolvable) and 3 (timeout).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated

import typer

from gsr.errors import GSRError

app = typer.Typer(
    name="gsr",
    help="Grounded scene-graph reasoning: parse, check, validate and plan robot manipulation tasks.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def _fail(message: str, code: int = 1) -> typer.Exit:
    typer.echo(f"error: {message}", err=True)
    return typer.Exit(code)


@app.command("parse")
def parse_cmd(
    file: Annotated[Path, typer.Argument(help="A PDDL domain/problem or a BDDL (LIBERO/BEHAVIOR) file.")],
) -> None:
    """Parse FILE and print it as normalized PDDL (exit 1 with file:line:column on bad input)."""
    from gsr.io import load_any, write_any

    typer.echo(write_any(load_any(file)), nl=False)


@app.command("validate")
def validate_cmd(
    files: Annotated[
        list[Path],
        typer.Argument(
            help="[DOMAIN] PROBLEM PLAN; for a BDDL problem the domain defaults to the tabletop domain."
        ),
    ],
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as JSON.")] = False,
) -> None:
    """Validate an IPC-format plan against a problem: exit 0 valid, 1 invalid (with the report)."""
    from gsr.io import load_domain_and_problem
    from gsr.plan_format import load_plan
    from gsr.validate import validate_plan

    if len(files) not in (2, 3):
        raise _fail("expected [DOMAIN] PROBLEM PLAN")
    domain_file = files[0] if len(files) == 3 else None
    problem_file, plan_file = files[-2], files[-1]
    domain, problem = load_domain_and_problem(domain_file, problem_file)
    report = validate_plan(domain, problem, load_plan(plan_file))
    typer.echo(json.dumps(report.to_dict(), indent=2) if as_json else str(report))
    raise typer.Exit(0 if report.valid else 1)


@app.command("plan")
def plan_cmd(
    files: Annotated[
        list[Path], typer.Argument(help="[DOMAIN] PROBLEM; a BDDL problem plans against the tabletop domain.")
    ],
    planner: Annotated[
        str, typer.Option(help="lazy-ff, gbfs-ff, astar-lmcut, astar-hmax, bfs or fd.")
    ] = "lazy-ff",
    timeout: Annotated[float, typer.Option(help="Time limit in seconds.")] = 60.0,
    out: Annotated[
        Path | None, typer.Option(help="Write the plan here (IPC format) instead of stdout.")
    ] = None,
) -> None:
    """Plan a problem: exit 0 solved, 2 proven unsolvable, 3 timeout, 1 error."""
    from gsr.plan.cli import plan_command

    if len(files) not in (1, 2):
        raise _fail("expected [DOMAIN] PROBLEM")
    domain_file = files[0] if len(files) == 2 else None
    raise typer.Exit(plan_command(domain_file, files[-1], planner, timeout, out))


schema_app = typer.Typer(help="Print JSON Schemas of GSR's data formats.", no_args_is_help=True)
app.add_typer(schema_app, name="schema")


@schema_app.command("scene-graph")
def schema_scene_graph() -> None:
    """JSON Schema of the scene-graph format."""
    from gsr.scene_graph import scene_graph_schema

    typer.echo(json.dumps(scene_graph_schema(), indent=2))


@app.command("check")
def check_cmd(
    scene: Annotated[Path, typer.Option(help="Scene graph: JSON or a GSR-Bench message {nodes, edges}.")],
    step: Annotated[str, typer.Option(help="A ground step such as '(pick red_cube1 table)'.")],
    as_json: Annotated[bool, typer.Option("--json", help="Print the diagnosis as JSON.")] = False,
) -> None:
    """Check one step against a scene graph with the tabletop domain: exit 0 valid, 1 invalid."""
    from gsr.check import check_step
    from gsr.facts import state_from_graph
    from gsr.io import load_scene
    from gsr.plan_format import parse_plan
    from gsr.resources import load_builtin_domain

    domain = load_builtin_domain()
    steps = parse_plan(step, source="--step").steps
    if len(steps) != 1:
        raise _fail(f"--step must hold exactly one step, got {len(steps)}")
    diagnosis = check_step(domain, state_from_graph(load_scene(scene), domain), steps[0])
    typer.echo(json.dumps(diagnosis.to_dict(), indent=2) if as_json else str(diagnosis))
    raise typer.Exit(0 if diagnosis.ok else 1)


@app.command("demo")
def demo_cmd(
    task: Annotated[
        Path | None, typer.Option(help="A LIBERO BDDL task file (default: the black-bowl drawer task).")
    ] = None,
) -> None:
    """Run the end-to-end demo: parse a LIBERO task, plan it, check every step, verify the goal."""
    from gsr.demo import run_demo

    raise typer.Exit(run_demo(task))


@app.command("serve")
def serve_cmd(
    host: Annotated[str, typer.Option(help="Interface to bind.")] = "127.0.0.1",
    port: Annotated[int, typer.Option(help="TCP port.")] = 8000,
    workers: Annotated[int, typer.Option(help="uvicorn worker processes.")] = 1,
    max_plan_seconds: Annotated[float | None, typer.Option(help="Planner budget per request (s).")] = None,
    max_concurrent: Annotated[int | None, typer.Option(help="Heavy requests running at once.")] = None,
) -> None:
    """Serve the HTTP reasoning API (OpenAPI at /openapi.json); limits also from GSR_SERVICE_* variables."""
    import os

    try:
        import uvicorn
    except ImportError:
        raise _fail("the service needs the 'serve' extra: pip install 'gsr[serve]'") from None
    if max_plan_seconds is not None:
        os.environ["GSR_SERVICE_MAX_PLAN_SECONDS"] = str(max_plan_seconds)
    if max_concurrent is not None:
        os.environ["GSR_SERVICE_MAX_CONCURRENT"] = str(max_concurrent)
    uvicorn.run("gsr.service.asgi:app", host=host, port=port, workers=workers, log_level="warning")


def main() -> None:
    """Console entry point: turn GSR errors into one-line messages and exit code 1."""
    try:
        app()
    except GSRError as exc:
        typer.echo(f"error: {exc}", err=True)
        sys.exit(1)
    except KeyboardInterrupt:
        typer.echo("interrupted", err=True)
        sys.exit(130)


if __name__ == "__main__":
    main()
