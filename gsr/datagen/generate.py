"""One shard of the dataset: a deterministic function of (seed, shard index, shard size).

A shard draws a small pool of scene structures, grounds each once, and then repeatedly reskins one
(new object types, colours, names, positions), samples a consistent initial state and plans a chain
of goals on it. Each scene gets a split: train, val (i.i.d. with train, other scenes) or test with a
held-out composition (``pair``: an unseen object-target pair, ``color``: an unseen colour,
``horizon``: a plan longer than any in train). Rows are emitted until the shard holds exactly its
size, so the dataset does not depend on how shards are spread over workers.
"""

from __future__ import annotations

import random
from collections import Counter
from dataclasses import dataclass, field
from typing import Any

from gsr.datagen.catalog import Catalog, load_catalog
from gsr.datagen.goals import HELDOUT_PAIRS, MAX_TRAIN_HORIZON, sample_goal
from gsr.datagen.samples import task_rows
from gsr.datagen.scene import Scene, initial_atoms, pair_key, reskin, sample_scene
from gsr.datagen.synth import GroundedScene, PlannedTask, SceneEngine
from gsr.pddl.model import Domain
from gsr.resources import load_builtin_domain

#: Probability of each scene kind: (split, held-out tag).
SCENE_KINDS: tuple[tuple[str, str | None, float], ...] = (
    ("train", None, 0.90),
    ("val", None, 0.04),
    ("test", "pair", 0.02),
    ("test", "color", 0.02),
    ("test", "horizon", 0.02),
)
POOL_SIZE = 8  # scene structures grounded per shard
TASKS_PER_SCENE = 8


@dataclass(slots=True)
class ShardResult:
    """Rows of one shard by split, plus counters for the manifest."""

    rows: dict[str, list[dict[str, Any]]]
    stats: Counter = field(default_factory=Counter)


def _kind(rng: random.Random) -> tuple[str, str | None]:
    r = rng.random()
    for split, tag, p in SCENE_KINDS:
        if r < p:
            return split, tag
        r -= p
    return "train", None


def _has_heldout_pair(atoms: frozenset, scene: Scene) -> bool:
    by = scene.by_id
    return any(
        a.predicate in ("on", "in") and pair_key(by[a.args[0]], by[a.args[1]]) in HELDOUT_PAIRS for a in atoms
    )


def _uses_heldout_pair(task: PlannedTask, scene: Scene) -> bool:
    by = scene.by_id
    return any(
        s.action in ("place_in", "place_on", "stack")
        and pair_key(by[s.args[0]], by[s.args[1]]) in HELDOUT_PAIRS
        for s in task.steps
    )


def _reskin_for(rng: random.Random, base: Scene, catalog: Catalog, heldout: str | None) -> Scene | None:
    """A reskin of ``base``; for the pair split one that can realise a held-out pair (None if 12 tries fail)."""
    if heldout != "pair":
        return reskin(rng, base, catalog, heldout)
    for _ in range(12):
        scene = reskin(rng, base, catalog, heldout)
        movers = [o for o in scene.objects if o.role == "item"]
        targets = [o for o in scene.objects if {"container", "supporter"} & o.affordances]
        if any(pair_key(o, t) in HELDOUT_PAIRS for o in movers for t in targets):
            return scene
    return None


def _keep(task: PlannedTask, scene: Scene, heldout: str | None) -> bool:
    """Whether a planned task belongs to its scene's split (held-out compositions stay out of train/val)."""
    long = len(task.steps) > MAX_TRAIN_HORIZON
    if heldout == "horizon":
        return long
    if long:
        return False
    if heldout == "pair":
        return True
    return not _uses_heldout_pair(task, scene)


def generate_shard(
    seed: int, shard: int, size: int, domain: Domain | None = None, catalog: Catalog | None = None
) -> ShardResult:
    """Exactly ``size`` rows for shard ``shard`` of the run with ``seed`` (same inputs, same rows)."""
    if domain is None:
        domain = load_builtin_domain("tabletop")
    catalog = catalog or load_catalog()
    rng = random.Random(f"gsr-datagen:{seed}:{shard}")
    result = ShardResult({"train": [], "val": [], "test": []})
    stats = result.stats
    pool: list[tuple[Scene, GroundedScene | None]] = []
    for _ in range(POOL_SIZE):
        base = sample_scene(rng, catalog, size=(2, 5))
        pool.append((base, None))
    emitted = 0
    scene_no = 0
    while emitted < size:
        scene_no += 1
        split, heldout = _kind(rng)
        slot = rng.randrange(len(pool))
        base, grounded = pool[slot]
        if grounded is None:
            grounded = GroundedScene(domain, base, initial_atoms(rng, base, HELDOUT_PAIRS))
            pool[slot] = (base, grounded)
            stats["groundings"] += 1
        scene = _reskin_for(rng, base, catalog, heldout)
        if scene is None:
            stats["scenes_without_heldout_pair"] += 1
            continue
        forbidden = frozenset() if heldout == "pair" else HELDOUT_PAIRS
        engine = SceneEngine(grounded, scene, initial_atoms(rng, scene, forbidden))
        if not engine.valid_start():
            stats["scenes_outside_grounding"] += 1
            continue
        stats["scenes"] += 1
        for task_no in range(TASKS_PER_SCENE):
            n = rng.choice((4, 5, 6)) if heldout == "horizon" else rng.choice((1, 1, 2, 2, 2, 3, 3))
            goal = sample_goal(rng, scene, engine.current(), n)
            if goal is None:
                stats["goals_unavailable"] += 1
                break
            task = engine.plan(goal)
            if task is None:
                stats["plans_failed"] += 1
                continue
            stats["plans_validated"] += 1
            if heldout != "pair" and _has_heldout_pair(engine.current(), scene):
                stats["tasks_dropped_split"] += 1
                break  # the scene now shows a held-out pair: it cannot feed train rows any more
            if not _keep(task, scene, heldout):
                stats["tasks_dropped_split"] += 1
                continue
            meta = {"split": split, "heldout": heldout or "", "task": f"{seed}-{shard}-{scene_no}-{task_no}"}
            rows = task_rows(scene, task, rng, meta)
            take = rows[: size - emitted]
            for r in take:
                result.rows[split].append({"id": f"{seed}-{shard:05d}-{emitted:06d}", **r})
                emitted += 1
                stats[f"rows_{r['type']}"] += 1
            stats["tasks"] += 1
            if emitted >= size:
                break
        stats["plans_rejected_by_checker"] += engine.rejected
    return result
