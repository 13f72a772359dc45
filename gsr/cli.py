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

from gsr.check import check_step
from gsr.cli_support import fail as _fail
from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.io import load_any, load_domain_and_problem, load_scene, write_any
from gsr.plan_format import load_plan, parse_plan
from gsr.reason.options import SolveOptions
from gsr.resources import load_builtin_domain
from gsr.scene_graph import scene_graph_schema
from gsr.validate import validate_plan

app = typer.Typer(
    name="gsr",
    help="Grounded scene-graph reasoning: parse, check, validate and plan robot manipulation tasks.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


@app.command("parse")
def parse_cmd(
    file: Annotated[Path, typer.Argument(help="A PDDL domain/problem or a BDDL (LIBERO/BEHAVIOR) file.")],
) -> None:
    """Parse FILE and print it as normalized PDDL (exit 1 with file:line:column on bad input)."""
    typer.echo(write_any(load_any(file)), nl=False)


@app.command("validate")
def validate_cmd(
    files: Annotated[
        list[Path],
        typer.Argument(
            help="[DOMAIN] PROBLEM PLAN; without DOMAIN a PDDL problem uses the domain file beside it (domain.pddl, NAME-domain.pddl, ...), a BDDL problem the tabletop domain."
        ),
    ],
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as JSON.")] = False,
) -> None:
    """Validate an IPC-format plan against a problem: exit 0 valid, 1 invalid (with the report)."""
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
        str, typer.Option(help="lazy-ff, lama, gbfs-ff, astar-lmcut, astar-hmax, astar-blind, bfs or fd.")
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
    typer.echo(json.dumps(scene_graph_schema(), indent=2))


@app.command("check")
def check_cmd(
    scene: Annotated[Path, typer.Option(help="Scene graph: JSON or a GSR-Bench message {nodes, edges}.")],
    step: Annotated[str, typer.Option(help="A ground step such as '(pick red_cube1 table)'.")],
    as_json: Annotated[bool, typer.Option("--json", help="Print the diagnosis as JSON.")] = False,
) -> None:
    """Check one step against a scene graph with the tabletop domain: exit 0 valid, 1 invalid."""
    domain = load_builtin_domain()
    steps = parse_plan(step, source="--step").steps
    if len(steps) != 1:
        raise _fail(f"--step must hold exactly one step, got {len(steps)}")
    diagnosis = check_step(domain, state_from_graph(load_scene(scene), domain), steps[0])
    typer.echo(json.dumps(diagnosis.to_dict(), indent=2) if as_json else str(diagnosis))
    raise typer.Exit(0 if diagnosis.ok else 1)


@app.command("serve")
def serve_cmd(
    host: Annotated[
        str, typer.Option(help="Interface to bind (not loopback: needs API keys or --insecure).")
    ] = "127.0.0.1",
    port: Annotated[int, typer.Option(help="TCP port.")] = 8000,
    workers: Annotated[
        int | None,
        typer.Option(help="uvicorn worker processes (default: GSR_SERVICE_WORKERS or one per core, max 4)."),
    ] = None,
    api_key_file: Annotated[
        Path | None, typer.Option(help="File of API keys, one per line (also GSR_SERVICE_API_KEYS).")
    ] = None,
    insecure: Annotated[bool, typer.Option(help="Allow a non-loopback bind without API keys.")] = False,
    log_json: Annotated[bool, typer.Option(help="Log one JSON object per line.")] = False,
    max_plan_seconds: Annotated[
        float | None, typer.Option(help="Time budget per plan/solve request (s).")
    ] = None,
    max_concurrent: Annotated[int | None, typer.Option(help="In-process requests computing at once.")] = None,
) -> None:
    """Serve the HTTP reasoning API (docs/service.md); keys and limits also from GSR_SERVICE_* variables."""
    try:
        from gsr.service.serve import serve
    except ImportError:
        raise _fail("the service needs the 'serve' extra: pip install 'gsr[serve]'") from None
    serve(host, port, workers, api_key_file, insecure, log_json, max_plan_seconds, max_concurrent)


@app.command("solve")
def solve_cmd(
    scene: Annotated[Path, typer.Option(help="Scene graph JSON, GSR-Bench message or LIBERO BDDL file.")],
    instruction_arg: Annotated[
        str | None, typer.Argument(metavar="[INSTRUCTION]", help="The instruction (or use --instruction).")
    ] = None,
    instruction: Annotated[
        str | None,
        typer.Option("--instruction", "-i", help="The instruction, e.g. 'put the red cube in the box'."),
    ] = None,
    fmt: Annotated[
        str, typer.Option("--format", help="text, json, pddl (IPC plan) or gsr-bench (move/open/close).")
    ] = "text",
    backend: Annotated[str, typer.Option(help="grounder, transformers:PATH or openai:MODEL.")] = "grounder",
    mode: Annotated[str, typer.Option(help="steps, goal or hybrid.")] = "steps",
    goal: Annotated[
        str | None, typer.Option(help="A PDDL goal to reach (default: from the instruction).")
    ] = None,
    domain: Annotated[Path | None, typer.Option(help="PDDL domain (default: tabletop).")] = None,
    max_steps: Annotated[int, typer.Option(help="Step limit.")] = 40,
    repairs: Annotated[int, typer.Option(help="Repair tries per step after a rejected answer.")] = 3,
    constrained: Annotated[bool, typer.Option(help="Constrained decoding (transformers backend).")] = False,
    base_url: Annotated[str | None, typer.Option(help="OpenAI-compatible base URL (openai backend).")] = None,
    transcript: Annotated[
        bool, typer.Option(help="With --format json: include every prompt and reply.")
    ] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Same as --format json.")] = False,
) -> None:
    """Reason from a scene to an instruction and print the checked plan: exit 0 with a plan, 1 when none was found."""
    from gsr.reason.cli import solve_command

    if (instruction is None) == (instruction_arg is None):
        raise _fail("give the instruction once: as an argument or with --instruction")
    options = SolveOptions(mode=mode, max_steps=max_steps, max_repairs=repairs, constrained=constrained)
    raise typer.Exit(
        solve_command(
            scene,
            instruction or instruction_arg or "",
            options,
            backend=backend,
            goal=goal,
            domain_file=domain,
            base_url=base_url,
            fmt=fmt,
            as_json=as_json,
            transcript=transcript,
        )
    )


reason_app = typer.Typer(help="The LLM reasoner's prompt and step language.", no_args_is_help=True)
app.add_typer(reason_app, name="reason")


@reason_app.command("prompt")
def reason_prompt_cmd(
    instruction: Annotated[str, typer.Argument(help="The instruction.")],
    scene: Annotated[Path, typer.Option(help="Scene graph JSON, GSR-Bench message or LIBERO BDDL file.")],
    mode: Annotated[str, typer.Option(help="steps or goal.")] = "steps",
    domain: Annotated[Path | None, typer.Option(help="PDDL domain (default: tabletop).")] = None,
) -> None:
    """Print the prompt the reasoner sends for the first step (or the goal)."""
    from gsr.reason.cli import prompt_command

    raise typer.Exit(prompt_command(scene, instruction, mode, domain))


@reason_app.command("check")
def reason_check_cmd(
    steps: Annotated[Path, typer.Argument(help="Step lines (text or JSON), e.g. a model's output.")],
    scene: Annotated[Path, typer.Option(help="Scene graph JSON, GSR-Bench message or LIBERO BDDL file.")],
    domain: Annotated[Path | None, typer.Option(help="PDDL domain (default: tabletop).")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as JSON.")] = False,
) -> None:
    """Parse step lines and check them in order against the scene: exit 0 all valid, 1 otherwise."""
    from gsr.reason.cli import check_command

    raise typer.Exit(check_command(scene, steps, as_json, domain))


data_app = typer.Typer(
    help="Reference data sets: fetch them from the package index, list what is present and where.",
    no_args_is_help=True,
)
app.add_typer(data_app, name="data")
CacheOption = Annotated[
    Path | None, typer.Option(help="The cache folder (default $GSR_CACHE or the user cache folder).")
]


@data_app.command("fetch")
def data_fetch_cmd(
    names: Annotated[list[str], typer.Argument(help="libero, behavior, pddlgym, or all.")],
    cache: CacheOption = None,
    force: Annotated[bool, typer.Option("--force", help="Fetch again even when present.")] = False,
) -> None:
    """Download sets from the package index into the cache: checksummed, atomic, idempotent."""
    from gsr.data_cli import fetch_command

    fetch_command(names, cache, force)


@data_app.command("list")
def data_list_cmd(cache: CacheOption = None) -> None:
    """Show every reference set: its copies (fetched, reference, shipped) and where, or how to get it."""
    from gsr.data_cli import list_text

    typer.echo(list_text(cache))


@data_app.command("path")
def data_path_cmd(
    name: Annotated[str, typer.Argument(help="A data set name (see gsr data list).")],
    cache: CacheOption = None,
) -> None:
    """Print the folder of a set's best copy (fetched, else reference, else shipped)."""
    from gsr.data_cli import path_command

    path_command(name, cache)


@app.command("datagen")
def datagen_cmd(
    out: Annotated[Path, typer.Option(help="Output directory (sharded JSONL, manifest, dataset card).")],
    samples: Annotated[int, typer.Option(help="Number of rows (samples) to generate.")],
    workers: Annotated[int, typer.Option(help="Parallel worker processes.")] = 1,
    backend: Annotated[str, typer.Option(help="local (processes) or ray.")] = "local",
    seed: Annotated[int, typer.Option(help="Random seed: same seed, byte-identical shards.")] = 0,
    resume: Annotated[bool, typer.Option(help="Continue an interrupted run in OUT.")] = False,
    shard_size: Annotated[int, typer.Option(help="Rows per shard (part of the dataset's identity).")] = 5000,
    progress: Annotated[bool, typer.Option(help="Show a progress bar on stderr.")] = True,
) -> None:
    """Generate a Manip-Cognition-style dataset of checked samples (see docs/dataset.md)."""
    from gsr.datagen.cli import datagen_command

    raise typer.Exit(datagen_command(out, samples, workers, backend, seed, resume, shard_size, progress))


@app.command("ground")
def ground_cmd(
    instruction: Annotated[
        str, typer.Argument(help="The instruction, e.g. 'put all red cubes in the blue box'.")
    ],
    scene: Annotated[
        Path, typer.Option(help="Scene graph: JSON, a GSR-Bench message {nodes, edges} or a BDDL file.")
    ],
    as_json: Annotated[bool, typer.Option("--json", help="Print the goal as JSON.")] = False,
) -> None:
    """Ground an instruction on a scene graph and print the goal as PDDL (exit 1 naming unknown words or candidates)."""
    from gsr.language.cli import ground_command

    raise typer.Exit(ground_command(scene, instruction, as_json))


@app.command("train")
def train_cmd(
    data: Annotated[Path, typer.Option(help="A dataset folder written by gsr datagen.")],
    model: Annotated[
        str,
        typer.Option(
            help="'tiny' (1.7M, CPU) or 'small' (12M, GPU) Llama trained from scratch, or a local checkpoint folder."
        ),
    ],
    out: Annotated[Path, typer.Option(help="Output folder (loads with --backend transformers:OUT).")],
    lora: Annotated[bool, typer.Option(help="Train LoRA adapters (peft) and merge them.")] = False,
    max_steps: Annotated[int, typer.Option(help="Optimizer steps.")] = 300,
    batch_size: Annotated[int, typer.Option(help="Examples per step.")] = 8,
    lr: Annotated[float | None, typer.Option(help="Learning rate (default by mode).")] = None,
    train_rows: Annotated[int, typer.Option(help="Training rows read from the train split.")] = 20000,
    eval_rows: Annotated[int, typer.Option(help="Validation rows for the reported loss.")] = 200,
    types: Annotated[str, typer.Option(help="Comma-separated sample types to train on.")] = (
        "next_action,goal_interpretation,forward_prediction"
    ),
    seed: Annotated[int, typer.Option(help="Random seed.")] = 0,
    time_budget: Annotated[
        float | None, typer.Option(help="Stop training after this many seconds (then evaluate and save).")
    ] = None,
) -> None:
    """Supervised fine-tuning on the reasoner's prompt/step format (see docs/training.md)."""
    from gsr.train.cli import train_command

    raise typer.Exit(
        train_command(
            data, model, out, lora, max_steps, batch_size, lr, train_rows, eval_rows, types, seed, time_budget
        )
    )


@app.command("datagen-tasks")
def datagen_tasks_cmd(
    data: Annotated[Path, typer.Option(help="A dataset folder written by gsr datagen.")],
    out: Annotated[
        Path, typer.Option(help="Folder for one TaskSpec JSON per task (run with gsr bench run tasks).")
    ],
    split: Annotated[str, typer.Option(help="train, val or test.")] = "test",
    heldout: Annotated[
        str | None, typer.Option(help="Only one held-out kind: pair, color or horizon.")
    ] = None,
    limit: Annotated[int | None, typer.Option(help="At most this many tasks.")] = None,
) -> None:
    """Export a generated dataset's tasks as TaskSpec files for the suites runner."""
    from gsr.datagen.tasks import export_tasks

    typer.echo(f"wrote {export_tasks(data, out, split, heldout, limit)} task(s) to {out}")


def _register_plugins(root: typer.Typer) -> None:
    """Add the commands of the upper layers (perception, benchmarks, delivery) and of other installed
    packages: each ``gsr.cli`` entry point names a ``register(app)`` function. The core never imports
    them by name, so the layering holds (tests/test_layers.py)."""
    from importlib.metadata import entry_points

    for ep in sorted(entry_points(group="gsr.cli"), key=lambda e: e.name):
        try:
            ep.load()(root)
        except Exception as exc:  # a broken plugin must not take the core commands down
            typer.echo(f"warning: gsr commands from {ep.name!r} ({ep.value}) not loaded: {exc}", err=True)


_register_plugins(app)


def main() -> None:
    """Console entry point: turn GSR errors into one-line messages and exit code 1."""
    try:
        app()
    except GSRError as exc:
        typer.echo(f"error: {exc}", err=True)
        sys.exit(1)
    except (RecursionError, MemoryError) as exc:  # e.g. a formula nested thousands deep
        typer.echo(f"error: the input is too large or too deeply nested ({type(exc).__name__})", err=True)
        sys.exit(1)
    except KeyboardInterrupt:
        typer.echo("interrupted", err=True)
        sys.exit(130)


if __name__ == "__main__":
    main()
