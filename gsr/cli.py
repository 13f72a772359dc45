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
        str, typer.Option(help="lazy-ff, gbfs-ff, astar-lmcut, astar-hmax, astar-blind, bfs or fd.")
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
    out: Annotated[Path, typer.Option(help="Output folder for the report.")] = Path("out/demo"),
    task: Annotated[
        Path | None, typer.Option(help="A LIBERO BDDL task file (default: the black-bowl drawer task).")
    ] = None,
    seed: Annotated[int, typer.Option(help="Simulator seed.")] = 0,
    perceive: Annotated[
        bool,
        typer.Option(
            "--perceive/--no-perceive",
            help="Scene graphs from the cameras (perception), or the simulator's ground truth.",
        ),
    ] = True,
    ground_truth: Annotated[bool, typer.Option("--ground-truth", help="Same as --no-perceive.")] = False,
    symbolic: Annotated[
        bool, typer.Option("--symbolic", help="Symbolic only: parse, plan, check (no simulator needed).")
    ] = False,
) -> None:
    """The end-to-end demo: PyBullet scene, perception, grounding, checked steps, execution, verification."""
    if symbolic:
        from gsr.demo import run_demo

        raise typer.Exit(run_demo(task))
    try:
        from benchmarks.demo import run_demo as run_physical
    except ImportError as exc:
        raise _fail(
            f"the physical demo needs the 'sim' and 'vision' extras ({exc}); try --symbolic"
        ) from None
    raise typer.Exit(run_physical(out, task, seed=seed, use_perception=perceive and not ground_truth))


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
    from perception.pipeline import perceive_files

    graph = perceive_files(rgb, depth, masks, camera, labels, out)
    if out is None:
        typer.echo(graph.to_json())
    else:
        typer.echo(f"wrote {out}: {len(graph.nodes)} nodes, {len(graph.edges)} edges", err=True)


@app.command("perceive-eval")
def perceive_eval_cmd(
    scenes: Annotated[int, typer.Option(help="Number of random scenes to render and perceive.")] = 20,
    seed: Annotated[int, typer.Option(help="Seed of the scene generator.")] = 0,
    depth_noise: Annotated[float, typer.Option(help="Gaussian depth noise sigma (m).")] = 0.0,
    mask_erosion: Annotated[int, typer.Option(help="Erode every instance mask by this many pixels.")] = 0,
    cameras: Annotated[int, typer.Option(help="Cameras per scene (fused).")] = 1,
    world: Annotated[
        str, typer.Option(help="skills (simulator tasks, scene_graph_from_sim truth) or procedural.")
    ] = "skills",
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as JSON.")] = False,
) -> None:
    """Render random PyBullet scenes, perceive them, score against ground truth (rendering not timed)."""
    if scenes < 1 or cameras < 1:
        raise _fail("--scenes and --cameras must be >= 1")
    if depth_noise < 0 or mask_erosion < 0:
        raise _fail("--depth-noise and --mask-erosion must be >= 0")
    if world not in ("skills", "procedural"):
        raise _fail(f"--world must be 'skills' or 'procedural', got {world!r}")
    from benchmarks.perception_eval import evaluate, format_report

    report = evaluate(scenes, seed, depth_noise, mask_erosion, cameras, world=world)
    typer.echo(json.dumps(report, indent=2) if as_json else format_report(report))


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
    raise typer.Exit(
        solve_command(
            scene,
            instruction or instruction_arg or "",
            backend,
            mode,
            as_json,
            goal,
            domain,
            max_steps,
            repairs,
            constrained,
            transcript,
            base_url,
            fmt,
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


delivery_app = typer.Typer(
    help="In-building delivery: buildings, people, delivery tasks, baseline runs.", no_args_is_help=True
)
app.add_typer(delivery_app, name="delivery")


@delivery_app.command("generate-building")
def delivery_generate_building(
    out: Annotated[Path, typer.Option(help="Write the building JSON here.")],
    seed: Annotated[int, typer.Option(help="Random seed: the same seed gives the same building.")] = 7,
    floors: Annotated[int, typer.Option(help="Number of floors (1-6).")] = 3,
    people: Annotated[int, typer.Option(help="Number of residents (at most 20).")] = 12,
    name: Annotated[str | None, typer.Option(help="Building name (default building-SEED).")] = None,
) -> None:
    """Generate a building from a seed, check its invariants and write it."""
    from benchmarks.delivery.cli import generate_building_command

    raise typer.Exit(generate_building_command(seed, out, floors, people, name))


@delivery_app.command("tasks")
def delivery_tasks(
    split: Annotated[str, typer.Option(help="train (2000), val (200) or test (1000).")] = "test",
    building: Annotated[Path | None, typer.Option(help="Building JSON (default: the shipped one).")] = None,
    limit: Annotated[int | None, typer.Option(help="Only the first N tasks.")] = None,
    out: Annotated[Path | None, typer.Option(help="Write JSON Lines here instead of printing.")] = None,
) -> None:
    """Generate the delivery tasks of a split (deterministic)."""
    from benchmarks.delivery.cli import tasks_command

    raise typer.Exit(tasks_command(split, building, limit, out))


@delivery_app.command("run")
def delivery_run(
    split: Annotated[str, typer.Option(help="train, val or test.")] = "test",
    building: Annotated[Path | None, typer.Option(help="Building JSON (default: the shipped one).")] = None,
    tasks: Annotated[
        Path | None, typer.Option(help="Run these tasks (JSON Lines) instead of a split.")
    ] = None,
    limit: Annotated[int | None, typer.Option(help="Only the first N tasks.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the summary as JSON.")] = False,
    out: Annotated[Path | None, typer.Option(help="Also write summary + per-episode results (JSON).")] = None,
    agent: Annotated[str, typer.Option(help="baseline, or the no-routines ablation.")] = "baseline",
    by_kind: Annotated[
        bool, typer.Option("--breakdown", help="Also break SR down by instruction kind.")
    ] = False,
) -> None:
    """Run the baseline delivery agent and print Task SR, parsing, manipulation and human-search SR."""
    from benchmarks.delivery.cli import run_command

    raise typer.Exit(run_command(split, building, tasks, limit, as_json, out, agent, by_kind))


@delivery_app.command("prs")
def delivery_prs(
    data: Annotated[Path, typer.Option(help="PRS data folder (env/data of prs-delivery).")],
    tasks: Annotated[Path, typer.Option(help="PRS task file (JSON keyed by task id).")],
    out: Annotated[Path, typer.Option(help="Output folder: results.json, prs_submission.json, report.html.")],
    workers: Annotated[int, typer.Option(help="Worker processes.")] = 1,
    captions: Annotated[
        str,
        typer.Option(
            help="Object captions for the sensor: dev (the data folder's dev tasks), none, or a task file."
        ),
    ] = "dev",
    crossfit: Annotated[
        int,
        typer.Option(help="K >= 2: K-fold estimate (calibration, captions from the other folds); 0: off."),
    ] = 0,
) -> None:
    """Run the PRS delivery benchmark in the offline PRS environment, scored by PRS's rules."""
    from benchmarks.delivery.prs_cli import prs_command

    raise typer.Exit(prs_command(data, tasks, out, workers, captions, crossfit))


@delivery_app.command("schedule")
def delivery_schedule(
    person: Annotated[str, typer.Argument(help="Person id or name, e.g. imani.")],
    seed: Annotated[int, typer.Option(help="World seed of the day.")] = 0,
    building: Annotated[Path | None, typer.Option(help="Building JSON (default: the shipped one).")] = None,
) -> None:
    """Show a person's published routine and their actual day under a world seed."""
    from benchmarks.delivery.cli import schedule_command

    raise typer.Exit(schedule_command(person, seed, building))


@delivery_app.command("map")
def delivery_map(
    floor: Annotated[int, typer.Option(help="Floor level (0 = ground).")] = 0,
    at: Annotated[str, typer.Option("--time", help="Time of day, HH:MM.")] = "12:00",
    seed: Annotated[int, typer.Option(help="World seed of the day.")] = 0,
    building: Annotated[Path | None, typer.Option(help="Building JSON (default: the shipped one).")] = None,
) -> None:
    """Print a floor's occupancy grid with the people on it at a time of day."""
    from benchmarks.delivery.cli import map_command

    raise typer.Exit(map_command(floor, at, seed, building))


@delivery_app.command("episode")
def delivery_episode(
    task: Annotated[str, typer.Argument(help="Task id, e.g. test-0004.")],
    building: Annotated[Path | None, typer.Option(help="Building JSON (default: the shipped one).")] = None,
    agent: Annotated[str, typer.Option(help="baseline, or the no-routines ablation.")] = "baseline",
) -> None:
    """Run one delivery task and print the agent's timeline."""
    from benchmarks.delivery.cli import episode_command

    raise typer.Exit(episode_command(task, building, agent))


bench_app = typer.Typer(
    help="Benchmark suites: list them, run an agent on one (reports), export tasks.", no_args_is_help=True
)
app.add_typer(bench_app, name="bench")


@bench_app.command("list")
def bench_list_cmd() -> None:
    """List the benchmark suites and built-in agents."""
    from benchmarks.cli import list_text

    typer.echo(list_text())


@bench_app.command("run")
def bench_run_cmd(
    suite: Annotated[
        str, typer.Argument(help="gsr-bench, gsr-bench-gen, libero, rlbench, tasks, delivery or prs.")
    ],
    source: Annotated[
        str | None, typer.Option(help="Suite input (GSR-Bench YAML, LIBERO folder, delivery building JSON).")
    ] = None,
    tasks: Annotated[
        str | None, typer.Option(help="Run TaskSpec JSON/YAML files (delivery: a JSON Lines task file).")
    ] = None,
    agent: Annotated[
        str | None,
        typer.Option(
            help="planner (default), grounder, reasoner, random or module:factory; delivery: baseline, no-routines."
        ),
    ] = None,
    split: Annotated[str | None, typer.Option(help="delivery: train, val or test (default test).")] = None,
    agent_opt: Annotated[list[str] | None, typer.Option(help="Agent option key=value (repeatable).")] = None,
    trials: Annotated[int, typer.Option(help="Episodes per task.")] = 1,
    seed: Annotated[int, typer.Option(help="Seed for generated suites and agents.")] = 0,
    workers: Annotated[int, typer.Option(help="Local worker processes.")] = 1,
    backend: Annotated[str, typer.Option(help="local or ray.")] = "local",
    address: Annotated[str | None, typer.Option(help="Ray cluster address (backend ray).")] = None,
    limit: Annotated[int | None, typer.Option(help="Only the first N tasks.")] = None,
    max_steps: Annotated[int, typer.Option(help="Step limit per episode.")] = 200,
    retries: Annotated[int, typer.Option(help="Re-asks after a rejected step (diagnosis fed back).")] = 0,
    reference: Annotated[
        str | None, typer.Option(help="Also plan with this planner for plan length vs reference.")
    ] = None,
    out: Annotated[str | None, typer.Option(help="Write results.json, report.md, report.html here.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print results.json to stdout.")] = False,
    physical: Annotated[
        bool, typer.Option("--physical", help="Execute steps in PyBullet (skills, headless), closed loop.")
    ] = False,
    perceive: Annotated[
        bool,
        typer.Option(
            "--perceive", help="With --physical: the agent sees perceived graphs (cameras), not truth."
        ),
    ] = False,
) -> None:
    """Run an agent on a suite: every step checked, goal scored; exit 0 when all episodes succeed, else 1."""
    from benchmarks.cli import run, summary_text

    doc = run(
        suite,
        source=source,
        tasks=tasks,
        agent=agent,
        agent_options=agent_opt,
        trials=trials,
        seed=seed,
        workers=workers,
        backend=backend,
        address=address,
        limit=limit,
        max_steps=max_steps,
        retries=retries,
        reference=reference,
        out=out,
        split=split,
        physical=physical,
        perceive=perceive,
    )
    typer.echo(json.dumps(doc, indent=2) if as_json else summary_text(doc))
    raise typer.Exit(0 if doc["success_rate"] == 1.0 else 1)


@bench_app.command("export")
def bench_export_cmd(
    suite: Annotated[str, typer.Argument(help="The suite to export.")],
    out: Annotated[str, typer.Option(help="Folder for one TaskSpec JSON per task.")],
    source: Annotated[str | None, typer.Option(help="Suite input (GSR-Bench YAML, LIBERO folder).")] = None,
    seed: Annotated[int, typer.Option(help="Seed for generated suites.")] = 0,
) -> None:
    """Write a suite's tasks as TaskSpec JSON files (run them later with --tasks)."""
    from benchmarks.cli import export

    typer.echo(f"wrote {export(suite, out, source, seed)} task(s) to {out}")


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
