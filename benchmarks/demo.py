"""The main job (``make demo`` / ``gsr demo``): perceive, ground, reason, check, execute, re-perceive, verify.

The LIBERO kitchen scene "put the black bowl in the bottom drawer of the cabinet and close it" is built in
PyBullet from its BDDL file; RGB-D from four cameras (instance masks from the simulator's segmentation
buffer only with ``--oracle-masks``; by default a detector segments and names the objects and perception
makes its own node ids) is perceived into a scene graph; the instruction is grounded into a goal over that graph; the
reasoner produces state-transition steps, each validated by the checker; the meta-skills execute them on the
simulated Panda, one at a time; the scene is perceived again and the goal is verified on the new graph.
It lives in ``benchmarks`` because it uses every layer (skills, perception, gsr).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import typer
from gsr.benchmarks.demo_report import DemoRecord, write_report
from gsr.benchmarks.suites.libero_suite import task_from_bddl
from gsr.perception.detect import load_detector
from gsr.skills import build_world, default_views, render, run_step, scene_graph_from_sim
from gsr.skills.perceived_scene import PerceivedScene, contradicted_effects
from gsr.skills.result import Failure, SkillResult

from gsr.demo import default_task_path
from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.graph_svg import scene_graph_svg
from gsr.language import ground
from gsr.pddl.writer import write_formula
from gsr.reason import solve
from gsr.resources import load_builtin_domain
from gsr.semantics import goal_holds
from gsr.step import Step
from gsr.transition import StepRejected, apply_step

T = TypeVar("T")


def _stage(rec: DemoRecord, name: str, fn: Callable[[], T], note: Callable[[T], str] = lambda _: "") -> T:
    """Run one stage, time it, print and record it."""
    t0 = time.perf_counter()
    value = fn()
    seconds = time.perf_counter() - t0
    text = note(value)
    rec.stages.append((name, seconds, text))
    typer.echo(f"[{seconds:6.2f} s] {name}" + (f": {text}" if text else ""))
    return value


def run_demo(
    out: Path = Path("out/demo"),
    task_path: Path | None = None,
    seed: int = 0,
    use_perception: bool = True,
    backend: str = "grounder",
    mode: str = "goal",
    oracle_masks: bool = False,
) -> int:
    """Run the physical demo; writes ``out`` and returns the exit code (0 only when the goal is verified)."""
    path = task_path or default_task_path()
    if not path.is_file():
        raise GSRError(f"{path}: task file not found (pass --task FILE)")
    domain = load_builtin_domain()
    task = task_from_bddl(path)
    rec = DemoRecord(task=path.name, instruction=task.instruction, perceived=use_perception)
    typer.echo(f"instruction: {task.instruction}")
    world = _stage(
        rec, "build PyBullet world", lambda: build_world(task, seed=seed), lambda w: f"seed {seed}"
    )
    try:
        views = default_views(world)
        detector = None
        if use_perception and not oracle_masks:
            detector = load_detector()
            if getattr(detector, "model", True) is None:
                # torch is not part of the demo's install, so no model can be trained here in seconds, and
                # the geometry-only detector names no bowls or drawers: say so, and use the labelled masks
                oracle_masks = True
                note = (
                    "no trained detector weights (perception/model or $GSR_PERCEPTION_MODEL; train them with "
                    "`gsr perceive-train --out DIR`): perceiving from the simulator's labelled masks instead"
                )
                typer.echo(f"note: {note}")
                rec.stages.append(("detector", 0.0, note))
        # cameras + perception, the known map, the gripper and object permanence (shared with the runner)
        scene = PerceivedScene(world, oracle_masks=oracle_masks, detector=detector)
        perception_kind = "simulator masks" if oracle_masks else "detector, no oracle"

        def observe(label: str, expected: Any = None) -> Any:
            picture = dataclasses.replace(
                views["front"], width=640, height=480
            )  # larger, for the report only
            rec.images[f"rgb_{label}"] = render(world, picture).rgb
            return scene.observe(expected) if use_perception else scene_graph_from_sim(world)

        def in_world(step: Any) -> Any:
            """The step on the bodies its perceived nodes are (the arm reaches where perception saw them)."""
            if not use_perception:
                return step
            return Step(step.action, tuple(scene.world_id(a) for a in step.args))

        def execute(step: Any) -> Any:
            """Run a step on the bodies its nodes are; a perceived node that is no body is a failed step."""
            known = {n.id for n in world.graph.nodes}  # map regions keep the world's ids
            unbound = [a for a in step.args if use_perception and scene.world_id(a) not in known]
            if unbound:
                return SkillResult(
                    step.action,
                    str(step),
                    False,
                    Failure.UNSUPPORTED,
                    f"perception's {', '.join(unbound)} is no object the arm can reach (a detection with "
                    "no body at its place)",
                )
            return run_step(world, in_world(step))

        def summary(g: Any) -> str:
            return f"{len(g.nodes)} nodes, {len(g.edges)} edges"

        before = _stage(
            rec,
            f"perceive RGB-D -> scene graph ({perception_kind})" if use_perception else "ground-truth graph",
            lambda: observe("before"),
            summary,
        )
        try:
            goal = _stage(
                rec,
                "ground instruction -> goal",
                lambda: ground(task.instruction, before),
                lambda g: write_formula(g.formula).replace("\n", " "),
            )
        except (
            GSRError
        ) as exc:  # the perceived scene lacks what the instruction names: a verdict, not a crash
            rec.verdict = f"grounding failed on the perceived scene graph: {exc}"
            return _finish(rec, out, before, None)
        rec.goal = " ".join(write_formula(goal.formula).split())
        reasoned = _stage(
            rec,
            f"reason ({backend}, {mode} mode) -> checked steps",
            lambda: solve(before, task.instruction, backend=backend, mode=mode, domain=domain, goal=goal),
            lambda r: f"{r.status}, {len(r.steps)} steps",
        )
        if not reasoned.success:
            rec.verdict = f"no valid plan: {reasoned.message}"
            return _finish(rec, out, before, None)
        typer.echo("executing checked steps with the meta-skills, re-perceiving after each:")
        executed_all, belief = True, before
        for checked in reasoned.steps:
            result = _stage(
                rec,
                f"execute {checked.step}",
                lambda s=checked.step: execute(s),
                lambda r: "ok" if r.ok else f"{r.failure}: {r.message}",
            )
            # closed loop: what the sensors show now, merged into the belief; the step's expected graph is
            # the prior only for what no sensor shows (power states, a part the cameras do not pick out)
            try:
                expected = apply_step(belief, checked.step, domain)
            except StepRejected:  # the belief moved away from the plan: no prior beyond the belief
                expected = None
            belief = observe("after", expected)
            missing = contradicted_effects(checked.diagnosis, belief, domain)
            rec.steps.append(
                {
                    "step": str(checked.step),
                    "check": checked.diagnosis.message or "ok: preconditions hold",
                    "executed": result.ok and not missing,
                    "execution": ("ok" if result.ok else f"{result.failure}: {result.message}")
                    + (f"; not observed: {', '.join(missing)}" if missing else ""),
                }
            )
            if not result.ok or missing:
                executed_all = False
                break
        after = belief
        rec.stages.append(
            ("re-perceived scene graph", 0.0, f"{len(after.nodes)} nodes, {len(after.edges)} edges")
        )
        truth = scene_graph_from_sim(world)
        if use_perception:  # the goal names perceived nodes: read the truth in those ids
            truth = scene.in_perceived_ids(truth)  # (identity with the simulator's masks)
        perceived_ok = goal_holds(domain, goal, state_from_graph(after, domain))
        truth_ok = goal_holds(domain, goal, state_from_graph(truth, domain))
        rec.verified = executed_all and perceived_ok
        if rec.verified:
            rec.verdict = "goal verified on the re-perceived scene graph" + (
                "" if truth_ok else " (but NOT in the simulator's ground truth)"
            )
            rec.verified = truth_ok
        elif not executed_all:
            rec.verdict = "execution stopped: a skill failed (see the plan table)"
        else:
            rec.verdict = "all steps executed but the goal does not hold in the re-perceived scene graph"
        return _finish(rec, out, before, after, scene_graph_svg)
    finally:
        world.close()


def _finish(
    rec: DemoRecord, out: Path, before: Any, after: Any, svg: Callable[..., str] | None = None
) -> int:

    svg = svg or scene_graph_svg
    moved = sorted({a for s in rec.steps for a in s["step"].strip("()").split()[1:2]})
    rec.svgs["graph_before"] = svg(before, title="scene graph before", highlight=moved)
    rec.graphs["graph_before"] = before.model_dump(mode="json", exclude_none=True)
    if after is not None:
        rec.svgs["graph_after"] = svg(after, title="scene graph after", highlight=moved)
        rec.graphs["graph_after"] = after.model_dump(mode="json", exclude_none=True)
    report = write_report(rec, out)
    typer.echo(("GOAL VERIFIED: " if rec.verified else "FAILED: ") + rec.verdict)
    typer.echo(f"report: {report}")
    return 0 if rec.verified else 1
