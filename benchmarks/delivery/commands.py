"""The delivery benchmark's `gsr delivery …` commands (registered through the ``gsr.cli`` entry point group)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def register(app: typer.Typer) -> None:
    """Add the ``gsr delivery`` group to the ``gsr`` command."""

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
        from gsr.benchmarks.delivery.cli import generate_building_command

        raise typer.Exit(generate_building_command(seed, out, floors, people, name))

    @delivery_app.command("tasks")
    def delivery_tasks(
        split: Annotated[str, typer.Option(help="train (2000), val (200) or test (1000).")] = "test",
        building: Annotated[
            Path | None, typer.Option(help="Building JSON (default: the shipped one).")
        ] = None,
        limit: Annotated[int | None, typer.Option(help="Only the first N tasks.")] = None,
        out: Annotated[Path | None, typer.Option(help="Write JSON Lines here instead of printing.")] = None,
    ) -> None:
        """Generate the delivery tasks of a split (deterministic)."""
        from gsr.benchmarks.delivery.cli import tasks_command

        raise typer.Exit(tasks_command(split, building, limit, out))

    @delivery_app.command("run")
    def delivery_run(
        split: Annotated[str, typer.Option(help="train, val or test.")] = "test",
        building: Annotated[
            Path | None, typer.Option(help="Building JSON (default: the shipped one).")
        ] = None,
        tasks: Annotated[
            Path | None, typer.Option(help="Run these tasks (JSON Lines) instead of a split.")
        ] = None,
        limit: Annotated[int | None, typer.Option(help="Only the first N tasks.")] = None,
        as_json: Annotated[bool, typer.Option("--json", help="Print the summary as JSON.")] = False,
        out: Annotated[
            Path | None, typer.Option(help="Also write summary + per-episode results (JSON).")
        ] = None,
        agent: Annotated[str, typer.Option(help="baseline, or the no-routines ablation.")] = "baseline",
        by_kind: Annotated[
            bool, typer.Option("--breakdown", help="Also break SR down by instruction kind.")
        ] = False,
    ) -> None:
        """Run the baseline delivery agent and print Task SR, parsing, manipulation and human-search SR."""
        from gsr.benchmarks.delivery.cli import run_command

        raise typer.Exit(run_command(split, building, tasks, limit, as_json, out, agent, by_kind))

    @delivery_app.command("prs")
    def delivery_prs(
        data: Annotated[Path, typer.Option(help="PRS data folder (env/data of prs-delivery).")],
        tasks: Annotated[Path, typer.Option(help="PRS task file (JSON keyed by task id).")],
        out: Annotated[
            Path, typer.Option(help="Output folder: results.json, prs_submission.json, report.html.")
        ],
        workers: Annotated[int, typer.Option(help="Worker processes.")] = 1,
        captions: Annotated[
            str,
            typer.Option(
                help="Object captions for the sensor: dev (the data folder's dev tasks), none, or a task file."
            ),
        ] = "dev",
        crossfit: Annotated[
            int,
            typer.Option(
                help="K >= 2: K-fold estimate (calibration, captions from the other folds); 0: off."
            ),
        ] = 0,
        split: Annotated[
            str,
            typer.Option(
                help="How --crossfit folds the tasks: position (file order), person (no recipient in two "
                "folds) or object (no target object in two folds: its caption never comes from its fold)."
            ),
        ] = "position",
    ) -> None:
        """Run the PRS delivery benchmark in the offline PRS environment, scored by PRS's rules."""
        from gsr.benchmarks.delivery.prs_cli import prs_command

        raise typer.Exit(prs_command(data, tasks, out, workers, captions, crossfit, split=split))

    @delivery_app.command("schedule")
    def delivery_schedule(
        person: Annotated[str, typer.Argument(help="Person id or name, e.g. imani.")],
        seed: Annotated[int, typer.Option(help="World seed of the day.")] = 0,
        building: Annotated[
            Path | None, typer.Option(help="Building JSON (default: the shipped one).")
        ] = None,
    ) -> None:
        """Show a person's published routine and their actual day under a world seed."""
        from gsr.benchmarks.delivery.cli import schedule_command

        raise typer.Exit(schedule_command(person, seed, building))

    @delivery_app.command("map")
    def delivery_map(
        floor: Annotated[int, typer.Option(help="Floor level (0 = ground).")] = 0,
        at: Annotated[str, typer.Option("--time", help="Time of day, HH:MM.")] = "12:00",
        seed: Annotated[int, typer.Option(help="World seed of the day.")] = 0,
        building: Annotated[
            Path | None, typer.Option(help="Building JSON (default: the shipped one).")
        ] = None,
    ) -> None:
        """Print a floor's occupancy grid with the people on it at a time of day."""
        from gsr.benchmarks.delivery.cli import map_command

        raise typer.Exit(map_command(floor, at, seed, building))

    @delivery_app.command("episode")
    def delivery_episode(
        task: Annotated[str, typer.Argument(help="Task id, e.g. test-0004.")],
        building: Annotated[
            Path | None, typer.Option(help="Building JSON (default: the shipped one).")
        ] = None,
        agent: Annotated[str, typer.Option(help="baseline, or the no-routines ablation.")] = "baseline",
    ) -> None:
        """Run one delivery task and print the agent's timeline."""
        from gsr.benchmarks.delivery.cli import episode_command

        raise typer.Exit(episode_command(task, building, agent))
