"""Generated rows: schemas, checker agreement of every target, held-out splits, determinism."""

from __future__ import annotations

import json
from collections import defaultdict

import pytest

from gsr.check import check_step
from gsr.datagen.generate import generate_shard
from gsr.datagen.goals import HELDOUT_PAIRS, MAX_TRAIN_HORIZON
from gsr.datagen.scene import HELDOUT_COLORS
from gsr.datagen.schema import SAMPLE_TYPES, decode, schemas_json
from gsr.facts import state_from_graph
from gsr.pddl.parser import parse_formula
from gsr.reason.step_format import parse_step_line
from gsr.resources import load_builtin_domain
from gsr.semantics import holds
from gsr.step import Step
from gsr.transition import apply_step
from gsr.validate import validate_plan


@pytest.fixture(scope="module")
def domain():
    return load_builtin_domain()


@pytest.fixture(scope="module")
def shard():
    # shard 1 of seed 4 holds train, val and test rows (checked below)
    return generate_shard(4, 1, 1500)


def _rows(shard):
    return [r for split in ("train", "val", "test") for r in shard.rows[split]]


def _step(data: dict) -> Step:
    line = f"({' '.join([data['action'], *data['args']])})"
    line += "".join(f" +{a}" for a in data.get("add") or ()) + "".join(
        f" -{a}" for a in data.get("delete") or ()
    )
    return parse_step_line(line)


def test_shard_has_exact_size_all_types_and_decodes(shard) -> None:
    rows = _rows(shard)
    assert len(rows) == 1500
    assert len({r["id"] for r in rows}) == 1500
    assert {r["type"] for r in rows} == set(SAMPLE_TYPES)
    for r in rows:
        envelope, _inp, _out = decode(r)  # validates every graph as a SceneGraph
        assert envelope.split in ("train", "val", "test")
    assert set(schemas_json()["types"]) == set(SAMPLE_TYPES)


def test_next_action_targets_pass_the_checker_with_complete_effects(shard, domain) -> None:
    n = 0
    for r in _rows(shard):
        if r["type"] != "next_action":
            continue
        _, inp, out = decode(r)
        if out.done:
            goal = parse_formula(inp.goal)
            assert holds(domain, goal, state_from_graph(inp.graph, domain))
            continue
        diagnosis = check_step(domain, state_from_graph(inp.graph, domain), _step(out.step.model_dump()))
        assert diagnosis.ok, (r["id"], str(diagnosis))
        n += 1
    assert n > 100


def test_forward_prediction_matches_apply_step(shard, domain) -> None:
    n = 0
    for r in _rows(shard):
        if r["type"] != "forward_prediction":
            continue
        _, inp, out = decode(r)
        nxt = apply_step(inp.graph, _step(inp.step.model_dump()), domain)
        assert state_from_graph(nxt, domain).atoms == state_from_graph(out.graph, domain).atoms, r["id"]
        n += 1
    assert n > 100


def test_inverse_plans_validate_and_goals_hold(shard, domain) -> None:
    by_task = defaultdict(dict)
    for r in _rows(shard):
        by_task[r["task"]].setdefault(r["type"], r)
    checked = 0
    for rows in by_task.values():
        if "inverse_action" not in rows or "goal_interpretation" not in rows:
            continue  # the last task of a shard may be cut off
        _, inp, out = decode(rows["inverse_action"])
        _, _, goal = decode(rows["goal_interpretation"])
        plan = [Step(s.action, tuple(s.args)) for s in out.plan]
        report = validate_plan(
            domain, state_from_graph(inp.start_graph, domain), plan, parse_formula(goal.goal)
        )
        assert report.valid, report.message
        assert report.final_state.atoms == state_from_graph(inp.goal_graph, domain).atoms
        assert len(plan) == rows["inverse_action"]["horizon"]
        checked += 1
    assert checked > 20


def test_scene_abstraction_lists_every_node(shard) -> None:
    for r in _rows(shard):
        if r["type"] == "scene_abstraction":
            _, inp, out = decode(r)
            assert sorted(o.id for o in inp.objects) == sorted(n.id for n in out.graph.nodes)
            assert all(len(o.position) == 3 and o.caption for o in inp.objects)


def _pairs_and_colors(row) -> tuple[set, set]:
    inp, out = json.loads(row["input"]), json.loads(row["output"])
    text = json.dumps([inp, out])
    colors = {c for c in HELDOUT_COLORS if f'"color":"{c}"' in text.replace(" ", "")}
    return colors, set()


def test_train_and_val_hold_no_heldout_composition(shard) -> None:
    from gsr.datagen.catalog import load_catalog

    kinds = {o.name for o in load_catalog().objects}
    assert kinds
    for split in ("train", "val"):
        for r in shard.rows[split]:
            assert r["heldout"] == ""
            assert r["horizon"] <= MAX_TRAIN_HORIZON
            colors, _ = _pairs_and_colors(r)
            assert not colors, r["id"]
    tags = {r["heldout"] for r in shard.rows["test"]}
    assert tags and tags <= {"pair", "color", "horizon"}
    for r in shard.rows["test"]:
        if r["heldout"] == "horizon":
            assert r["horizon"] > MAX_TRAIN_HORIZON
        if r["heldout"] == "color":
            assert _pairs_and_colors(r)[0]
    assert HELDOUT_PAIRS


def test_heldout_pairs_only_in_pair_test_rows() -> None:
    """Rebuild the (object type, target type) pair of every goal relation from the generator's scenes."""
    import random

    from gsr.datagen.catalog import load_catalog
    from gsr.datagen.goals import sample_goal
    from gsr.datagen.scene import initial_atoms, pair_key, reskin, sample_scene

    catalog = load_catalog()
    rng = random.Random(3)
    for _ in range(30):
        base = sample_scene(rng, catalog)
        scene = reskin(rng, base, catalog, None)
        atoms = initial_atoms(rng, scene, HELDOUT_PAIRS)
        assert not any(
            a.predicate in ("on", "in")
            and pair_key(scene.by_id[a.args[0]], scene.by_id[a.args[1]]) in HELDOUT_PAIRS
            for a in atoms
        )
        goal = sample_goal(rng, scene, atoms, 2)
        if goal:
            assert not any(
                pair_key(scene.by_id[g.args[0]], scene.by_id[g.args[1]]) in HELDOUT_PAIRS
                for g in goal
                if len(g.args) == 2
            )
        assert not any(o.color in HELDOUT_COLORS for o in scene.objects)


def test_same_seed_same_rows_other_seed_other_rows(shard) -> None:
    again = generate_shard(4, 1, 1500)
    assert again.rows == shard.rows
    other = generate_shard(5, 1, 300)
    assert other.rows["train"][0]["input"] != shard.rows["train"][0]["input"]
