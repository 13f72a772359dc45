"""Generated suites: the nine GSR-Bench cells, the RLBench-style suite and LIBERO; counts, ids, seeds."""

from __future__ import annotations

from collections import Counter

import pytest
from gsr.benchmarks.runner import RunConfig, run_tasks
from gsr.benchmarks.suites.gsr_bench_gen import CELLS, LEVELS, generate_cell, generate_gsr_bench
from gsr.benchmarks.suites.libero_suite import load_libero, task_from_bddl
from gsr.benchmarks.suites.rlbench import CATEGORIES, generate_rlbench

from gsr.errors import GSRError
from gsr.task_spec import task_json


def test_gsr_bench_cells_180_tasks() -> None:
    tasks = generate_gsr_bench(seed=0)
    assert len(tasks) == 180 and len({t.id for t in tasks}) == 180
    cells = Counter((t.category, t.level) for t in tasks)
    assert cells == {(c, lv): 20 for c in CELLS for lv in LEVELS}
    assert all(t.suite == "gsr-bench-gen" for t in tasks)


def test_generators_are_deterministic_per_seed() -> None:
    a = [task_json(t) for t in generate_cell(CELLS[1], "Complex", 5, seed=3)]
    b = [task_json(t) for t in generate_cell(CELLS[1], "Complex", 5, seed=3)]
    c = [task_json(t) for t in generate_cell(CELLS[1], "Complex", 5, seed=4)]
    assert a == b and a != c
    assert [task_json(t) for t in generate_rlbench(7)] == [task_json(t) for t in generate_rlbench(7)]
    assert [task_json(t) for t in generate_rlbench(7)] != [task_json(t) for t in generate_rlbench(8)]


def test_rlbench_100_tasks_in_5_categories() -> None:
    tasks = generate_rlbench(0)
    assert len(tasks) == 100 and len({t.id for t in tasks}) == 100
    assert Counter(t.category for t in tasks) == {c: 20 for c in CATEGORIES}
    families = {t.metadata["family"] for t in tasks}
    for name in (
        "open_drawer",
        "put_item_in_drawer",
        "close_microwave",
        "turn_tap",
        "lamp_on",
        "push_button",
    ):
        assert name in families
    assert {"stack_blocks", "stack_cups"} <= families
    assert all(t.layout is not None and t.layout.objects for t in tasks)


def test_libero_40_tasks(libero_dir) -> None:
    tasks = load_libero(libero_dir)
    assert len(tasks) == 40 and len({t.id for t in tasks}) == 40
    assert Counter(t.category for t in tasks) == {
        "libero_10": 10,
        "libero_goal": 10,
        "libero_object": 10,
        "libero_spatial": 10,
    }
    t = next(t for t in tasks if "open_the_top_drawer_and_put_the_bowl_inside" in t.id)
    assert t.instruction == "Open the top layer of the drawer and put the bowl inside"
    assert "wooden_cabinet_1/top_drawer" in t.goal
    assert any(r.name == "main_table_plate_region" for r in t.layout.regions)


def test_bad_libero_inputs(tmp_path) -> None:
    with pytest.raises(GSRError, match="no such LIBERO folder"):
        load_libero(tmp_path / "nope")
    with pytest.raises(GSRError, match=r"no \.bddl task files"):
        load_libero(tmp_path)
    bad = tmp_path / "bad.bddl"
    bad.write_text("(define (problem x) (:domain robosuite)")
    with pytest.raises(GSRError, match=r"bad\.bddl"):
        task_from_bddl(bad)


def _solve_all(tasks: list) -> list:
    results = run_tasks(tasks, RunConfig(agent="planner"))
    failures = [(r.id, r.reason) for r in results if not r.success]
    assert not failures
    return results


def test_planner_solves_fast_subsets(libero_dir) -> None:
    _solve_all(generate_rlbench(0)[::4])
    _solve_all(load_libero(libero_dir)[::5])
    results = _solve_all([generate_cell(c, lv, 1, seed=0)[0] for c in CELLS for lv in ("Simple",)])
    assert all(r.steps > 10 for r in results)


@pytest.mark.slow
def test_planner_solves_everything(libero_dir) -> None:
    _solve_all(generate_rlbench(0))
    _solve_all(load_libero(libero_dir))
    results = _solve_all(generate_gsr_bench(0))
    by_cell: dict[tuple, list[int]] = {}
    for r in results:
        by_cell.setdefault((r.category, r.level), []).append(r.steps)
    assert all(sum(v) / len(v) > 10 for v in by_cell.values()), by_cell
