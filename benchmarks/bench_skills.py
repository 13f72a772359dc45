"""Meta-skill benchmark: per-skill physical success over seeded scenes, and a 10-step episode's wall time.

Each trial builds a fresh world (PyBullet DIRECT) from a seeded scene graph: a three-drawer cabinet,
a stove and a few objects drawn from the catalogue, laid out by ``gsr.skills.layout.layout_from_graph``.
Setup steps (e.g. the pick before a place) run physically too; a trial whose setup fails is counted
as ``setup_failed`` and left out of the skill's success rate (so each rate is conditional on reaching
the skill). Success means the skill reported ok, i.e. its own effect holds in the simulator.

With ``--suite NAME[:SOURCE]`` it instead runs the planner agent on a task suite with physical
execution (``gsr.skills.sim_executor.SimExecutor`` in ``gsr.benchmarks.runner.run_episode``) and reports the
physical success per category (``--level Simple`` keeps one level, ``--limit N`` the first N tasks).

Usage: python benchmarks/bench_skills.py [--trials 50] [--skills pick,place_on,...] [--episodes 5]
       [--seed 0] [--workers 1] [--save FILE] [--markdown]
       python benchmarks/bench_skills.py --suite libero:data/libero/libero_goal [--markdown]
       python benchmarks/bench_skills.py --suite gsr-bench-gen --level Simple [--markdown]
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import random
import statistics
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

from gsr.benchmarks import runner
from gsr.benchmarks.agents import make_agent
from gsr.benchmarks.suites import get_suite
from gsr.skills.build import build_world
from gsr.skills.camera import default_views, render, save_png
from gsr.skills.executor import execute_plan
from gsr.skills.library import run_step
from gsr.skills.sim_executor import SimExecutor

from gsr.diagnosis import Diagnosis
from gsr.errors import GSRError
from gsr.resources import load_builtin_domain
from gsr.scene_graph import Edge, Node, SceneGraph
from gsr.step import Step
from gsr.task_spec import TaskSpec, task_from_dict

PICKABLE = (
    "cube",
    "bowl",
    "plate",
    "mug",
    "milk",
    "ketchup",
    "alphabet_soup",
    "cream_cheese",
    "wine_bottle",
    "book",
    "box",
    "basket",
    "butter",
    "popcorn",
)
SMALL = ("cube", "cream_cheese", "butter", "milk", "alphabet_soup", "chocolate_pudding", "mug")
COLORS = ("red", "blue", "green", "yellow", "white", "orange")
SKILLS = (
    "pick",
    "place_on",
    "place_in",
    "stack",
    "open",
    "close",
    "open_door",
    "close_door",
    "turn_on",
    "turn_off",
    "push",
)
DRAWERS = {0: "bottom_drawer", 1: "middle_drawer", 2: "top_drawer"}


def scene(
    rng: random.Random,
    movables: list[tuple[str, str]],
    states: dict[str, tuple[str, ...]] | None = None,
    extra: list[Node] | None = None,
) -> SceneGraph:
    """Table, cabinet (3 drawers + top), stove and the given (id, category) objects, all on the table."""
    states = states or {}
    nodes = [
        Node(id="table", category="table"),
        Node(id="cabinet_1", category="cabinet", attributes={"fixture": True}),
        Node(id="cabinet_1/top_side", category="cabinet_top", parent="cabinet_1"),
        Node(
            id="stove_1",
            category="stove",
            states=states.get("stove_1", ("off",)),
            attributes={"fixture": True},
        ),
    ]
    for level, name in DRAWERS.items():
        nid = f"cabinet_1/{name}"
        nodes.append(
            Node(
                id=nid,
                category="drawer",
                parent="cabinet_1",
                attributes={"level": level},
                states=states.get(nid, ("closed",)),
            )
        )
    edges = [
        Edge(source="cabinet_1", relation="on", target="table"),
        Edge(source="stove_1", relation="on", target="table"),
    ]
    for nid, cat in movables:
        attrs = (
            {"color": rng.choice(COLORS)} if cat in ("cube", "block", "box", "basket", "mug", "book") else {}
        )
        nodes.append(Node(id=nid, category=cat, attributes=attrs, states=states.get(nid, ())))
        edges.append(Edge(source=nid, relation="on", target="table"))
    for n in extra or []:
        nodes.append(n)
        if n.parent is None:
            edges.append(Edge(source=n.id, relation="on", target="table"))
    return SceneGraph(nodes=tuple(nodes), edges=tuple(edges))


def _task(graph: SceneGraph, seed: int) -> TaskSpec:
    return TaskSpec(
        id=f"bench-{seed}", suite="bench-skills", instructions=("bench",), initial=graph, goal="(and)"
    )


def _distinct(rng: random.Random, pool: tuple[str, ...], k: int) -> list[str]:
    return rng.sample(list(pool), k)


# each trial: seed -> (graph, setup steps, the step under test)
def trial_pick(rng: random.Random) -> tuple[SceneGraph, list[Step], Step]:
    cats = _distinct(rng, PICKABLE, 3)
    objs = [(f"{c}_{i}", c) for i, c in enumerate(cats)]
    target = rng.choice(objs)[0]
    return scene(rng, objs), [], Step("pick", (target, "table"))


def trial_place_on(rng: random.Random) -> tuple[SceneGraph, list[Step], Step]:
    x = rng.choice(SMALL)
    support = rng.choice(("plate", "bowl", "stove_1", "cabinet_1/top_side"))
    objs = [(f"{x}_1", x)] + ([(f"{support}_1", support)] if support in ("plate", "bowl") else [])
    objs.append((f"distractor_{rng.choice(PICKABLE)}", rng.choice(("cube", "milk", "mug"))))
    target = f"{support}_1" if support in ("plate", "bowl") else support
    return scene(rng, objs), [Step("pick", (f"{x}_1", "table"))], Step("place_on", (f"{x}_1", target))


def trial_place_in(rng: random.Random) -> tuple[SceneGraph, list[Step], Step]:
    x = rng.choice(("cube", "cream_cheese", "butter", "chocolate_pudding", "alphabet_soup"))
    container = rng.choice(("box", "basket", "drawer"))
    objs = [(f"{x}_1", x)]
    states: dict[str, tuple[str, ...]] = {}
    if container == "drawer":
        target = f"cabinet_1/{DRAWERS[2]}"  # only the top drawer may be open for a put-in (domain rule)
        states[target] = ("open",)
    else:
        target = f"{container}_1"
        objs.append((target, container))
    return scene(rng, objs, states), [Step("pick", (f"{x}_1", "table"))], Step("place_in", (f"{x}_1", target))


def trial_stack(rng: random.Random) -> tuple[SceneGraph, list[Step], Step]:
    objs = [("block_1", "block"), ("block_2", "block"), ("cube_3", "cube")]
    return scene(rng, objs), [Step("pick", ("block_1", "table"))], Step("stack", ("block_1", "block_2"))


def _openable(rng: random.Random, is_open: bool) -> tuple[SceneGraph, str]:
    kind = rng.choice(("drawer", "drawer", "lidded_box"))
    if kind == "drawer":
        nid = f"cabinet_1/{DRAWERS[rng.randrange(3)]}"
        return scene(rng, [("cube_1", "cube")], {nid: ("open",) if is_open else ("closed",)}), nid
    box = Node(
        id="lid_box_1",
        category="lidded_box",
        attributes={"color": rng.choice(COLORS)},
        states=("open",) if is_open else ("closed",),
    )
    return scene(rng, [("cube_1", "cube")], extra=[box]), "lid_box_1"


def trial_open(rng: random.Random) -> tuple[SceneGraph, list[Step], Step]:
    graph, nid = _openable(rng, False)
    return graph, [], Step("open", (nid,))


def trial_close(rng: random.Random) -> tuple[SceneGraph, list[Step], Step]:
    graph, nid = _openable(rng, True)
    return graph, [], Step("close", (nid,))


def _microwave(rng: random.Random, is_open: bool) -> SceneGraph:
    """Cabinet, stove, a microwave whose door is open or closed, and one or two catalogue objects."""
    dev = Node(
        id="microwave_1",
        category="microwave",
        attributes={"fixture": True},
        states=("off", "open" if is_open else "closed"),
    )
    objs = [(f"{c}_{i + 1}", c) for i, c in enumerate(_distinct(rng, SMALL, rng.randint(1, 2)))]
    return scene(rng, objs, extra=[dev])


def trial_open_door(rng: random.Random) -> tuple[SceneGraph, list[Step], Step]:
    return _microwave(rng, False), [], Step("open", ("microwave_1",))


def trial_close_door(rng: random.Random) -> tuple[SceneGraph, list[Step], Step]:
    return _microwave(rng, True), [], Step("close", ("microwave_1",))


def _switchable(rng: random.Random, on: bool) -> tuple[SceneGraph, str]:
    kind = rng.choice(("stove", "lamp", "microwave"))
    state = ("on",) if on else ("off",)
    if kind == "stove":
        return scene(rng, [("cube_1", "cube")], {"stove_1": state}), "stove_1"
    dev = Node(id=f"{kind}_1", category=kind, attributes={"fixture": True}, states=state)
    return scene(rng, [("cube_1", "cube")], extra=[dev]), f"{kind}_1"


def trial_turn_on(rng: random.Random) -> tuple[SceneGraph, list[Step], Step]:
    graph, nid = _switchable(rng, False)
    return graph, [], Step("turn_on", (nid,))


def trial_turn_off(rng: random.Random) -> tuple[SceneGraph, list[Step], Step]:
    graph, nid = _switchable(rng, True)
    return graph, [], Step("turn_off", (nid,))


def trial_push(rng: random.Random) -> tuple[SceneGraph, list[Step], Step]:
    x = rng.choice(("plate", "box", "cube", "bowl", "cookie_box", "milk"))
    region = Node(id="table/stove_front_region", category="region", parent="table")
    graph = scene(rng, [(f"{x}_1", x)], extra=[region])
    return graph, [], Step("push", (f"{x}_1", "table", "table/stove_front_region"))


TRIALS: dict[str, Callable[[random.Random], tuple[SceneGraph, list[Step], Step]]] = {
    "pick": trial_pick,
    "place_on": trial_place_on,
    "place_in": trial_place_in,
    "stack": trial_stack,
    "open": trial_open,
    "close": trial_close,
    "open_door": trial_open_door,
    "close_door": trial_close_door,
    "turn_on": trial_turn_on,
    "turn_off": trial_turn_off,
    "push": trial_push,
}


def run_trial(job: tuple[str, int]) -> dict:
    """One seeded trial of one skill: build, run setup, run the skill; a JSON-ready record."""
    skill, seed = job
    rng = random.Random(f"{skill}-{seed}")
    graph, setup, step = TRIALS[skill](rng)
    t0 = time.perf_counter()
    record = {"skill": skill, "seed": seed, "step": str(step)}
    with build_world(_task(graph, seed), seed=seed) as world:
        for s in setup:
            r = run_step(world, s)
            if not r.ok:
                record.update(
                    setup_failed=True,
                    ok=False,
                    failure=r.failure.value if r.failure else None,
                    message=f"setup {s}: {r.message}",
                    wall_s=time.perf_counter() - t0,
                )
                return record
        t1 = time.perf_counter()
        r = run_step(world, step)
    record.update(
        setup_failed=False,
        ok=r.ok,
        failure=r.failure.value if r.failure else None,
        message=r.message,
        skill_wall_s=round(time.perf_counter() - t1, 3),
        sim_steps=r.sim_steps,
        wall_s=round(time.perf_counter() - t0, 3),
    )
    return record


EPISODE = [
    Step("open", ("cabinet_1/top_drawer",)),
    Step("pick", ("cube_1", "table")),
    Step("place_in", ("cube_1", "cabinet_1/top_drawer")),
    Step("close", ("cabinet_1/top_drawer",)),
    Step("turn_on", ("stove_1",)),
    Step("pick", ("bowl_1", "table")),
    Step("place_on", ("bowl_1", "plate_1")),
    Step("pick", ("milk_1", "table")),
    Step("place_on", ("milk_1", "cabinet_1/top_side")),
    Step("turn_off", ("stove_1",)),
]


def run_episode(seed: int) -> dict:
    """The 10-step episode (drawer, stove, three pick-and-places) closed loop; wall time with and without build."""
    rng = random.Random(f"episode-{seed}")
    graph = scene(rng, [("cube_1", "cube"), ("bowl_1", "bowl"), ("plate_1", "plate"), ("milk_1", "milk")])
    t0, c0 = time.perf_counter(), time.process_time()
    with build_world(_task(graph, seed), seed=seed) as world:
        t1 = time.perf_counter()
        result = execute_plan(world, EPISODE)
    # CPU time beside wall time: on a shared machine wall time also counts other people's processes
    return {
        "seed": seed,
        "ok": result.ok,
        "steps_done": sum(s.ok for s in result.steps),
        "diagnosis": result.diagnosis,
        "wall_s": round(time.perf_counter() - t0, 3),
        "execute_s": round(time.perf_counter() - t1, 3),
        "cpu_s": round(time.process_time() - c0, 3),
        "sim_steps": result.sim_steps,
    }


#: Recovery: failed physical steps in a row after which an episode stops (each failure makes the
#: planner agent replan from the observed scene graph), and an episode's CPU-time bound (s).
RETRIES, EPISODE_CPU_S = 3, 600.0


def cpu_bounded(executor: Any, cpu_budget: float) -> Any:
    """The executor with an episode CPU-time bound: once spent, every step is refused (no skill runs),
    so the runner's retry count ends the episode; a step already running finishes (skills are bounded
    by their own simulation-step budgets)."""
    start = time.process_time()
    execute = executor.execute

    def bounded_execute(step: Step) -> Diagnosis:
        spent = time.process_time() - start
        if spent > cpu_budget:
            executor.out_of_time = True
            return Diagnosis(
                ok=False,
                step=step,
                message=f"episode time bound: {spent:.0f} of {cpu_budget:.0f} CPU-s spent",
            )
        return execute(step)

    executor.execute = bounded_execute
    executor.out_of_time = False
    return executor


def run_suite_task(job: tuple[dict, int, int, float]) -> dict:
    """One suite task, planner agent, physical execution with bounded recovery; a JSON-ready record."""
    data, seed, retries, cpu_budget = job
    task = task_from_dict(data)
    ex = cpu_bounded(SimExecutor(seed=seed, frame_camera=None), cpu_budget)
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        r = runner.run_episode(
            task,
            make_agent("planner", {}),
            load_builtin_domain("tabletop"),
            seed=seed,
            retries=retries,
            executor=ex,
        )
        failures = [o.diagnosis for o in ex.outcomes if not o.ok]
    finally:
        ex.close()
    return {
        "id": task.id,
        "category": task.category or task.suite,
        "level": task.level,
        "success": r.success,
        "steps": r.steps,
        "recoveries": len(failures),
        "failures": failures,
        # neighbours set aside for refused picks (gsr.skills.recovery), with what followed
        "clearances": list(getattr(ex, "recoveries", [])),
        "out_of_time": ex.out_of_time,
        "reason": r.reason,
        "wall_s": round(time.perf_counter() - t0, 2),
        "cpu_s": round(time.process_time() - c0, 2),
    }


def suite_markdown(rows: list[dict]) -> str:
    """Physical success per category (and level) of a suite run."""
    groups: dict[tuple[str, str], list[dict]] = {}
    for r in rows:
        groups.setdefault((r["category"], r["level"] or "-"), []).append(r)
    lines = [
        "| category | level | tasks | physical success | wall s median / p95 | CPU s median / p95 "
        "| recovered | main failure |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for (cat, level), rs in [*sorted(groups.items()), (("all", "-"), rows)]:
        ok = sum(r["success"] for r in rs)
        fails = Counter(failure_kind(r["reason"]) for r in rs if not r["success"])
        main = ", ".join(f"{k} {v}" for k, v in fails.most_common(2)) or "-"
        wall, cpu = [r["wall_s"] for r in rs], [r.get("cpu_s", 0.0) for r in rs]
        recovered = sum(1 for r in rs if r["success"] and r.get("recoveries"))
        lines.append(
            f"| {cat} | {level} | {len(rs)} | {ok}/{len(rs)} ({100 * ok / len(rs):.0f}%) "
            f"| {statistics.median(wall):.1f} / {p95(wall):.1f} | {statistics.median(cpu):.1f} / {p95(cpu):.1f} "
            f"| {recovered} | {main} |"
        )
    return "\n".join(lines)


def p95(values: list[float]) -> float:
    """The 95th percentile (nearest rank)."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, max(0, -(-95 * len(ordered) // 100) - 1))]


def failure_kind(reason: str) -> str:
    for kind in (
        "unreachable",
        "blocked",
        "grasp_missed",
        "grasp_slipped",
        "timeout",
        "ik_flip",
        "not_achieved",
        "unsupported",
    ):
        if f"({kind})" in reason:
            return kind
    if "episode time bound" in reason:
        return "out_of_time"
    return "diverged" if "diverges" in reason else (reason.split(":")[0][:40] or "unknown")


def summarize(records: list[dict], episodes: list[dict]) -> dict:
    """Per-skill rates and failure counts, episode timing."""
    out: dict = {"skills": {}, "episodes": {}}
    for skill in SKILLS:
        rs = [r for r in records if r["skill"] == skill]
        if not rs:
            continue
        attempted = [r for r in rs if not r["setup_failed"]]
        ok = sum(r["ok"] for r in attempted)
        out["skills"][skill] = {
            "trials": len(rs),
            "attempted": len(attempted),
            "setup_failed": len(rs) - len(attempted),
            "succeeded": ok,
            "rate": round(ok / len(attempted), 3) if attempted else None,
            "failures": dict(Counter(r["failure"] for r in attempted if not r["ok"])),
            "median_skill_s": round(statistics.median(r["skill_wall_s"] for r in attempted), 2)
            if attempted
            else None,
        }
    if episodes:
        out["episodes"] = {
            "n": len(episodes),
            "succeeded": sum(e["ok"] for e in episodes),
            "median_wall_s": round(statistics.median(e["wall_s"] for e in episodes), 2),
            "max_wall_s": round(max(e["wall_s"] for e in episodes), 2),
            "median_execute_s": round(statistics.median(e["execute_s"] for e in episodes), 2),
            "median_cpu_s": round(statistics.median(e["cpu_s"] for e in episodes), 2),
        }
    return out


def markdown(summary: dict) -> str:
    """A markdown table of the summary."""
    lines = [
        "| skill | trials | reached | success | rate | failures (count) | median skill s |",
        "|---|---|---|---|---|---|---|",
    ]
    for skill, s in summary["skills"].items():
        fails = ", ".join(f"{k} {v}" for k, v in sorted(s["failures"].items())) or "-"
        rate = f"{100 * s['rate']:.0f}%" if s["rate"] is not None else "n/a"
        lines.append(
            f"| {skill} | {s['trials']} | {s['attempted']} | {s['succeeded']} | {rate} | {fails} | {s['median_skill_s']} |"
        )
    e = summary.get("episodes") or {}
    if e:
        lines.append("")
        lines.append(
            f"10-step episode: {e['succeeded']}/{e['n']} completed; wall time median {e['median_wall_s']} s, "
            f"max {e['max_wall_s']} s (execution only: median {e['median_execute_s']} s; "
            f"CPU time median {e['median_cpu_s']} s)."
        )
    return "\n".join(lines)


def _save(path: Path, data: dict) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent or ".", suffix=".tmp")
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        json.dump(data, fh, indent=2)
    os.replace(tmp, path)


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; print a markdown table; optionally save every trial record as JSON."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=50)
    ap.add_argument("--skills", default=",".join(SKILLS))
    ap.add_argument("--episodes", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--save", type=Path)
    ap.add_argument("--markdown", action="store_true")
    ap.add_argument("-v", "--verbose", action="store_true")
    ap.add_argument("--suite", help="NAME[:SOURCE]: run the planner agent on a suite physically instead")
    ap.add_argument("--level", help="with --suite: keep tasks of this level only (e.g. Simple)")
    ap.add_argument("--limit", type=int, help="with --suite: the first N tasks only")
    ap.add_argument("--category", help="with --suite: keep tasks whose category contains this (e.g. Spatial)")
    ap.add_argument(
        "--retries",
        type=int,
        default=RETRIES,
        help=f"with --suite: failed steps in a row the planner replans after (default {RETRIES})",
    )
    ap.add_argument(
        "--episode-cpu",
        type=float,
        default=EPISODE_CPU_S,
        help=f"with --suite: an episode's CPU-time bound in s (default {EPISODE_CPU_S:.0f})",
    )
    ap.add_argument("--figures", type=Path, help="write the docs figures (PNG) to this folder and exit")
    args = ap.parse_args(argv)
    if args.figures:
        for path in render_figures(args.figures):
            print(path)
        return 0
    if args.suite:
        return _main_suite(args)
    skills = [s.strip() for s in args.skills.split(",") if s.strip()]
    unknown = [s for s in skills if s not in TRIALS]
    if unknown:
        print(f"error: unknown skill(s) {', '.join(unknown)}; expected {', '.join(SKILLS)}", file=sys.stderr)
        return 2
    jobs = [(s, args.seed + i) for s in skills for i in range(args.trials)]
    t0 = time.perf_counter()
    records: list[dict] = []
    with multiprocessing.get_context("spawn").Pool(args.workers) if args.workers > 1 else _Serial() as pool:
        for rec in pool.imap(run_trial, jobs):
            records.append(rec)
            if args.verbose:
                print(
                    f"{rec['skill']:9s} seed {rec['seed']:3d} {'ok ' if rec['ok'] else 'FAIL'} "
                    f"{rec.get('failure') or ''} {rec['message'][:100]}",
                    file=sys.stderr,
                    flush=True,
                )
        episodes = list(pool.imap(run_episode, [args.seed + i for i in range(args.episodes)]))
    summary = summarize(records, episodes)
    summary["total_s"] = round(time.perf_counter() - t0, 1)
    if args.save:
        _save(args.save, {"summary": summary, "trials": records, "episodes": episodes})
    print(markdown(summary) if args.markdown else json.dumps(summary, indent=2))
    return 0


def render_figures(out: Path) -> list[Path]:
    """PNG figures for docs/skills.md: a 10-step episode's scene before and after, from two cameras."""
    from dataclasses import replace

    out.mkdir(parents=True, exist_ok=True)
    rng = random.Random("episode-0")
    graph = scene(rng, [("cube_1", "cube"), ("bowl_1", "bowl"), ("plate_1", "plate"), ("milk_1", "milk")])
    paths = []
    with build_world(_task(graph, 0), seed=0) as world:
        views = default_views(world)
        for when, plan in (("before", []), ("middle", EPISODE[:3]), ("after", EPISODE[3:])):
            execute_plan(world, plan)
            for name in ("front", "top"):
                path = out / f"skills-episode-{when}-{name}.png"
                save_png(render(world, replace(views[name], width=320, height=240)).rgb, str(path))
                paths.append(path)
    return paths


def _main_suite(args: argparse.Namespace) -> int:
    name, _, source = args.suite.partition(":")
    try:
        tasks = get_suite(name).tasks(source or None, args.seed)
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.level:
        tasks = [t for t in tasks if (t.level or "").lower() == args.level.lower()]
    if args.category:
        tasks = [t for t in tasks if args.category.lower() in (t.category or "").lower()]
    tasks = tasks[: args.limit] if args.limit else tasks
    if not tasks:
        print("error: no tasks selected", file=sys.stderr)
        return 2
    jobs = [(t.model_dump(mode="json"), args.seed, args.retries, args.episode_cpu) for t in tasks]
    rows: list[dict] = []
    with multiprocessing.get_context("spawn").Pool(args.workers) if args.workers > 1 else _Serial() as pool:
        for row in pool.imap(run_suite_task, jobs):
            rows.append(row)
            if args.verbose:
                print(
                    f"{row['id']:40s} {'ok ' if row['success'] else 'FAIL'} {row['reason'][:140]}",
                    file=sys.stderr,
                    flush=True,
                )
    if args.save:
        _save(args.save, {"suite": args.suite, "level": args.level, "tasks": rows})
    ok = sum(r["success"] for r in rows)
    print(
        suite_markdown(rows) if args.markdown else json.dumps({"succeeded": ok, "tasks": len(rows)}, indent=2)
    )
    return 0


class _Serial:
    """A stand-in for a process pool that runs jobs in this process."""

    def __enter__(self) -> _Serial:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def imap(self, fn, items):
        """Map lazily in-process."""
        return (fn(x) for x in items)


if __name__ == "__main__":
    raise SystemExit(main())
