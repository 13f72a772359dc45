"""Task generation: counts, determinism, and references that single out the right object and person."""

from __future__ import annotations

from pathlib import Path

import pytest
from gsr.benchmarks.delivery.agent import resolve_person
from gsr.benchmarks.delivery.tasks import SPLITS, TIME_LIMIT, generate_tasks, load_tasks, save_tasks

from gsr.errors import GSRError


def test_test_split_size_and_determinism(shipped) -> None:
    tasks = generate_tasks(shipped, "test")
    assert len(tasks) == SPLITS["test"][1] >= 900
    assert len({t.id for t in tasks}) == len(tasks)
    assert len({t.instruction for t in tasks}) > 0.9 * len(tasks)
    again = generate_tasks(shipped, "test", limit=50)
    assert again == tasks[:50]
    assert generate_tasks(shipped, "val", limit=50) != tasks[:50]
    assert all(t.time_limit == TIME_LIMIT == 480.0 for t in tasks)


def test_references_are_unambiguous(shipped, bmap) -> None:
    rec = {r.id: r for r in shipped.receptacles}
    for t in generate_tasks(shipped, "val"):
        o = t.reference.object
        hits = [
            it.id
            for it in shipped.items
            if it.category == o.category
            and (o.color is None or it.color == o.color)
            and (o.receptacle is None or rec[it.receptacle].category == o.receptacle)
            and (o.room is None or rec[it.receptacle].room == o.room)
        ]
        assert hits == [t.item], t.instruction
        assert resolve_person(shipped.people, t.reference.person) == [t.person], t.instruction
        assert bmap.is_walkable(t.start)
        assert shipped.person(t.person).name in t.instruction or t.reference.person.name is None


def test_unknown_split(shipped) -> None:
    with pytest.raises(ValueError, match="unknown split"):
        generate_tasks(shipped, "dev")


def test_jsonl_round_trip_and_errors(shipped, tmp_path: Path) -> None:
    tasks = generate_tasks(shipped, "val", limit=5)
    p = tmp_path / "t.jsonl"
    save_tasks(tasks, p)
    assert load_tasks(p) == tasks
    lines = p.read_text().splitlines()
    lines[2] = lines[2].replace('"start_time":', '"start_tim":')
    p.write_text("\n".join(lines))
    with pytest.raises(GSRError, match=r"t\.jsonl:3: invalid task"):
        load_tasks(p)
