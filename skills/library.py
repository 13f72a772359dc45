"""The meta-skill library: one physical skill per tabletop-domain action, run from a checked ``Step``.

``run_step(world, step)`` dispatches on ``step.action`` (pick, place_on, place_in, stack, open, close,
turn_on, turn_off, press, push), runs the skill inside a simulation-step budget (no skill can hang),
and checks the step's own effect in the simulator before reporting success. Failures are typed
(:class:`gsr.skills.result.Failure`).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from gsr.skills.articulated import operate, push
from gsr.skills.grasping import pick, place
from gsr.skills.motion import Motion
from gsr.skills.result import Failure, SkillError, SkillResult
from gsr.skills.sim_graph import support_of
from gsr.skills.world import World

from gsr.step import Step

DEFAULT_BUDGET = 15000  # simulation steps (62 s of simulated time) per skill


def _object(world: World, node_id: str):
    if node_id not in world.objects:
        raise SkillError(Failure.UNSUPPORTED, f"{node_id} is not a movable object of the world")
    return world.objects[node_id]


def settle_released(world: World, m: Motion, body: int, limit: int = 240) -> None:
    """Let a released object come to rest (bounded): a mug rocking on its rim is not yet anywhere."""
    import pybullet as p

    for _ in range(limit // 12):
        lin, ang = p.getBaseVelocity(body, physicsClientId=world.client)
        if max(map(abs, lin)) < 0.01 and max(map(abs, ang)) < 0.1:
            return
        m.step(12)


def _held_object(world: World, m: Motion, node_id: str):
    obj = _object(world, node_id)
    if support_of(world, node_id) != ("held", ""):
        raise SkillError(Failure.GRASP_SLIPPED, f"{node_id} is not in the hand")
    return obj


def _skill_pick(world: World, m: Motion, args: tuple[str, ...]) -> dict:
    obj = _object(world, args[0])
    pick(world, m, obj)
    return {"support": "held"}


def _place(relation: str) -> Callable[[World, Motion, tuple[str, ...]], dict]:
    def run(world: World, m: Motion, args: tuple[str, ...]) -> dict:
        obj = _held_object(world, m, args[0])
        place(world, m, obj, args[1], relation)
        settle_released(world, m, obj.body)
        got = support_of(world, obj.id)
        if got != (relation, args[1]):
            where = f"{got[0]} {got[1]}".strip() if got else "nowhere (still moving)"
            raise SkillError(Failure.NOT_ACHIEVED, f"{obj.id} ended {where}, not {relation} {args[1]}")
        return {"support": f"{relation} {args[1]}"}

    return run


def _articulated(kind: str) -> Callable[[World, Motion, tuple[str, ...]], dict]:
    def run(world: World, m: Motion, args: tuple[str, ...]) -> dict:
        return operate(world, m, args[0], kind)

    return run


def _push(world: World, m: Motion, args: tuple[str, ...]) -> dict:
    return push(world, m, args[0], args[2]) or {}


SKILLS: dict[str, Callable[[World, Motion, tuple[str, ...]], dict]] = {
    "pick": _skill_pick,
    "place_on": _place("on"),
    "place_in": _place("in"),
    "stack": _place("on"),
    "open": _articulated("open"),
    "close": _articulated("close"),
    "turn_on": _articulated("turn_on"),
    "turn_off": _articulated("turn_off"),
    "press": _articulated("press"),
    "push": _push,
}


def run_step(world: World, step: Step, budget: int = DEFAULT_BUDGET) -> SkillResult:
    """Execute one symbolic step physically; the result says whether its effect holds in the simulator."""
    t0 = time.perf_counter()
    m = Motion(world, budget)
    name = str(step)
    skill = SKILLS.get(step.action)
    if skill is None:
        return SkillResult(
            step.action, name, False, Failure.UNSUPPORTED, f"no skill for action {step.action!r}"
        )
    try:
        observed = skill(world, m, step.args)
    except SkillError as exc:
        return SkillResult(
            step.action, name, False, exc.failure, exc.message, m.used, time.perf_counter() - t0
        )
    return SkillResult(step.action, name, True, None, "", m.used, time.perf_counter() - t0, observed)
