"""The benchmark layer's `gsr` commands: demo, perceive-eval and the bench group (``gsr.cli`` entry points)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from gsr.cli_support import fail


def register(app: typer.Typer) -> None:
    """Add ``gsr demo``, ``gsr perceive-eval`` and ``gsr bench …`` to the ``gsr`` command."""

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
        oracle_masks: Annotated[
            bool,
            typer.Option(
                "--oracle-masks",
                help="Perceive from the simulator's labelled masks and ids (the earlier path) instead of the detector.",
            ),
        ] = False,
        symbolic: Annotated[
            bool, typer.Option("--symbolic", help="Symbolic only: parse, plan, check (no simulator needed).")
        ] = False,
    ) -> None:
        """The end-to-end demo: PyBullet scene, perception, grounding, checked steps, execution, verification."""
        if symbolic:
            from gsr.demo import run_demo

            raise typer.Exit(run_demo(task))
        try:
            from gsr.benchmarks.demo import run_demo as run_physical
        except ImportError as exc:
            raise fail(
                f"the physical demo needs the 'sim' and 'vision' extras ({exc}); try --symbolic"
            ) from None
        raise typer.Exit(
            run_physical(
                out, task, seed=seed, use_perception=perceive and not ground_truth, oracle_masks=oracle_masks
            )
        )

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
        no_oracle: Annotated[
            bool,
            typer.Option(
                "--no-oracle",
                help="RGB-D and cameras only: the detector segments and names the objects; nodes matched "
                "to the truth by 3D overlap (detector time included in frames/s).",
            ),
        ] = False,
        weights: Annotated[
            Path | None,
            typer.Option(help="With --no-oracle: detector weights (gsr perceive-train --out DIR)."),
        ] = None,
        seen_open: Annotated[
            bool,
            typer.Option(
                "--seen-open",
                help="With --no-oracle: earlier looks with each closed drawer, lid or door open (one per "
                "look), then the scene as it is; the tracked belief is scored (a separate protocol).",
            ),
        ] = False,
    ) -> None:
        """Render random PyBullet scenes, perceive them, score against ground truth (rendering not timed)."""
        if scenes < 1 or cameras < 1:
            raise fail("--scenes and --cameras must be >= 1")
        if depth_noise < 0 or mask_erosion < 0:
            raise fail("--depth-noise and --mask-erosion must be >= 0")
        if world not in ("skills", "procedural"):
            raise fail(f"--world must be 'skills' or 'procedural', got {world!r}")
        if no_oracle and mask_erosion:
            raise fail("--mask-erosion degrades the simulator's masks; --no-oracle uses none")
        if weights is not None and not no_oracle:
            raise fail("--weights needs --no-oracle")
        if seen_open and not (no_oracle and world == "skills"):
            raise fail("--seen-open needs --no-oracle and the skills world")
        from gsr.benchmarks.perception.eval import evaluate, format_report

        detector = None
        if no_oracle:
            from gsr.perception.detect import load_detector

            detector = load_detector(weights)
        report = evaluate(
            scenes,
            seed,
            depth_noise,
            mask_erosion,
            cameras,
            world=world,
            oracle=not no_oracle,
            detector=detector,
            seen_open=seen_open,
        )
        typer.echo(json.dumps(report, indent=2) if as_json else format_report(report))

    @app.command("perceive-train")
    def perceive_train_cmd(
        out: Annotated[Path, typer.Option(help="Folder for model.npz, model.json and MODEL_CARD.md.")],
        scenes: Annotated[int, typer.Option(help="Random simulator scenes to render for training.")] = 150,
        views: Annotated[int, typer.Option(help="Camera poses per scene.")] = 6,
        heldout_scenes: Annotated[
            int, typer.Option(help="Held-out scenes for the model card (0: none).")
        ] = 20,
        seed: Annotated[int, typer.Option(help="Seed of the scene, camera and training streams.")] = 0,
        threads: Annotated[int, typer.Option(help="Torch threads.")] = 1,
    ) -> None:
        """Train the no-oracle detector (merge + recognition MLPs) on rendered scenes; CPU only."""
        if scenes < 2 or views < 1 or heldout_scenes < 0 or threads < 1:
            raise fail("--scenes must be >= 2, --views and --threads >= 1, --heldout-scenes >= 0")
        from gsr.benchmarks.perception.train_data import run_training

        from gsr.errors import GSRError

        try:
            meta = run_training(
                str(out), scenes, views, heldout_scenes, seed, threads, log=lambda m: typer.echo(m, err=True)
            )
        except GSRError as exc:
            raise fail(str(exc)) from None
        typer.echo(f"wrote {out}: {len(meta['categories'])} categories, validation {meta['validation']}")

    bench_app = typer.Typer(
        help="Benchmark suites: list them, run an agent on one (reports), export tasks.", no_args_is_help=True
    )
    app.add_typer(bench_app, name="bench")

    @bench_app.command("list")
    def bench_list_cmd() -> None:
        """List the benchmark suites and built-in agents."""
        from gsr.benchmarks.cli import list_text

        typer.echo(list_text())

    @bench_app.command("run")
    def bench_run_cmd(
        suite: Annotated[
            str, typer.Argument(help="gsr-bench, gsr-bench-gen, libero, rlbench, tasks, delivery or prs.")
        ],
        source: Annotated[
            str | None,
            typer.Option(help="Suite input (GSR-Bench YAML, LIBERO folder, delivery building JSON)."),
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
        split: Annotated[
            str | None, typer.Option(help="delivery: train, val or test (default test).")
        ] = None,
        agent_opt: Annotated[
            list[str] | None, typer.Option(help="Agent option key=value (repeatable).")
        ] = None,
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
        out: Annotated[
            str | None, typer.Option(help="Write results.json, report.md, report.html here.")
        ] = None,
        as_json: Annotated[bool, typer.Option("--json", help="Print results.json to stdout.")] = False,
        physical: Annotated[
            bool,
            typer.Option("--physical", help="Execute steps in PyBullet (skills, headless), closed loop."),
        ] = False,
        perceive: Annotated[
            bool,
            typer.Option(
                "--perceive",
                help="With --physical: the agent sees perceived graphs (cameras + detector, no simulator "
                "masks or ids), not truth.",
            ),
        ] = False,
        oracle_masks: Annotated[
            bool,
            typer.Option(
                "--oracle-masks",
                help="With --perceive: segment with the simulator's labelled masks (the earlier path) "
                "instead of the detector.",
            ),
        ] = False,
    ) -> None:
        """Run an agent on a suite: every step checked, goal scored; exit 0 when all episodes succeed, else 1."""
        from gsr.benchmarks.cli import run, summary_text

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
            oracle_masks=oracle_masks,
        )
        typer.echo(json.dumps(doc, indent=2) if as_json else summary_text(doc))
        raise typer.Exit(0 if doc["success_rate"] == 1.0 else 1)

    @bench_app.command("export")
    def bench_export_cmd(
        suite: Annotated[str, typer.Argument(help="The suite to export.")],
        out: Annotated[str, typer.Option(help="Folder for one TaskSpec JSON per task.")],
        source: Annotated[
            str | None, typer.Option(help="Suite input (GSR-Bench YAML, LIBERO folder).")
        ] = None,
        seed: Annotated[int, typer.Option(help="Seed for generated suites.")] = 0,
    ) -> None:
        """Write a suite's tasks as TaskSpec JSON files (run them later with --tasks)."""
        from gsr.benchmarks.cli import export

        typer.echo(f"wrote {export(suite, out, source, seed)} task(s) to {out}")
