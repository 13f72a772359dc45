"""Task suites: each loads (or generates, by seed) a list of TaskSpecs.

``gsr-bench`` (the public config file), ``gsr-bench-gen`` (the nine generated cells), ``libero`` (a
folder of BDDL task files), ``rlbench`` (100 generated RLBench-style tasks) and ``tasks`` (a folder or
file of TaskSpec JSON/YAML, e.g. exported with ``gsr bench export``); ``delivery`` (in-building delivery)
is an *episode suite*: it runs its own episodes on the runner's pool and scores them with its own
metrics (``gsr.episode.EpisodeSuite``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from importlib import import_module
from pathlib import Path
from typing import Any

from gsr.benchmarks.suites.gsr_bench import load_gsr_bench
from gsr.benchmarks.suites.gsr_bench_gen import generate_gsr_bench
from gsr.benchmarks.suites.libero_suite import load_libero
from gsr.benchmarks.suites.rlbench import generate_rlbench

from gsr.data_sets import locate
from gsr.errors import GSRError
from gsr.resources import shared_data_dir
from gsr.task_spec import TaskSpec, load_task


def shared_data() -> Path:
    """Where the third-party reference data lies: $GSR_SHARED_DATA or ../shared/data beside the checkout."""
    return shared_data_dir()


@dataclass(frozen=True)
class Suite:
    """A named suite: a description, its default source (if it reads files) and its loader.

    ``episodes`` names (``module:attr``, imported lazily) an ``EpisodeSuite`` for suites whose episodes
    are not TaskSpecs; such a suite has no TaskSpec loader.
    """

    name: str
    description: str
    load: Callable[[Path | None, int], list[TaskSpec]] | None = None
    default_source: Callable[[], Path] | None = None
    episodes: str | None = None

    def episode_suite(self) -> Any | None:
        """The suite's ``EpisodeSuite`` object (None for a TaskSpec suite)."""
        if self.episodes is None:
            return None
        module, _, attr = self.episodes.partition(":")
        return getattr(import_module(module), attr)

    def tasks(self, source: str | Path | None = None, seed: int = 0) -> list[TaskSpec]:
        """The suite's tasks from ``source`` (or the default) and ``seed``."""
        if self.load is None:
            raise GSRError(
                f"suite {self.name} runs its own episodes, not TaskSpecs: run it with gsr bench run {self.name}"
            )
        path = (
            Path(source) if source is not None else (self.default_source() if self.default_source else None)
        )
        if path is not None and not path.exists():
            hint = " or set GSR_SHARED_DATA; see gsr data list" if self.name == "gsr-bench" else ""
            raise GSRError(f"suite {self.name}: {path} does not exist (pass --source PATH{hint})")
        return self.load(path, seed)


def _gsr_bench(path: Path | None, seed: int) -> list[TaskSpec]:
    assert path is not None
    return load_gsr_bench(path)


def _gsr_bench_gen(path: Path | None, seed: int) -> list[TaskSpec]:
    return generate_gsr_bench(seed)


def _libero(path: Path | None, seed: int) -> list[TaskSpec]:
    assert path is not None
    return load_libero(path)


def _rlbench(path: Path | None, seed: int) -> list[TaskSpec]:
    return generate_rlbench(seed)


def load_task_files(path: Path | None, seed: int = 0) -> list[TaskSpec]:
    """TaskSpecs from a JSON/YAML file or every such file under a folder (sorted); ids must be unique."""
    if path is None:
        raise GSRError("suite tasks: pass --tasks PATH (a TaskSpec file or a folder of them)")
    files = (
        [path]
        if path.is_file()
        else sorted(p for p in path.rglob("*") if p.suffix.lower() in (".json", ".yaml", ".yml"))
    )
    if not files:
        raise GSRError(f"{path}: no TaskSpec .json/.yaml files found")
    tasks = [load_task(f) for f in files]
    seen: dict[str, Path] = {}
    for f, t in zip(files, tasks, strict=True):
        if t.id in seen:
            raise GSRError(f"{f}: duplicate task id {t.id!r} (also in {seen[t.id]})")
        seen[t.id] = f
    return tasks


SUITES: dict[str, Suite] = {
    s.name: s
    for s in (
        Suite(
            "gsr-bench",
            "GSR-Bench configs (public saved_configs.yaml format); goals from the query semantics",
            _gsr_bench,
            lambda: shared_data() / "gsr_bench" / "saved_configs_dev.yaml",
        ),
        Suite("gsr-bench-gen", "the nine GSR-Bench cells, 20 seeded tasks each (180)", _gsr_bench_gen),
        Suite(
            "libero",
            "every LIBERO BDDL task file of a folder (default: the fetched 130, else the shipped 40)",
            _libero,
            lambda: locate("libero"),
        ),
        Suite("rlbench", "100 RLBench-style tasks in 5 categories (seeded)", _rlbench),
        Suite("tasks", "TaskSpec JSON/YAML files (a file or a folder)", load_task_files),
        Suite(
            "delivery",
            "in-building delivery (PRS-style): train 2000 / val 200 / test 1000 tasks, shipped building",
            episodes="gsr.benchmarks.delivery.suite:SUITE",
        ),
        Suite(
            "prs",
            "the PRS delivery benchmark's own station, people and tasks (--source PRS data folder), PRS's rules",
            episodes="gsr.benchmarks.delivery.prs_suite:SUITE",
        ),
    )
}


def get_suite(name: str) -> Suite:
    """The suite ``name``; a clear error listing the known ones otherwise."""
    try:
        return SUITES[name]
    except KeyError:
        raise GSRError(f"unknown suite {name!r}; choose one of {', '.join(SUITES)}") from None
