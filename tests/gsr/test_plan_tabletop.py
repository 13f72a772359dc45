"""Planner on the tabletop domain (LIBERO, GSR-Bench graphs, generated long tasks) and on negative preconditions."""

from __future__ import annotations

import functools
import itertools
from pathlib import Path

import pytest
from gsr.benchmarks.bench_planner import long_tabletop_task, long_tabletop_tasks

from gsr.facts import problem_from_graph
from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.pddl.model import And, Atom, Not
from gsr.pddl.parser import parse_domain, parse_problem
from gsr.plan import plan, plan_graph
from gsr.plan.fast_downward import find_fast_downward, run_fast_downward
from gsr.plan.grounding import ground_task
from gsr.plan.heuristics import Relaxation
from gsr.resources import load_builtin_domain
from gsr.step import Goal
from gsr.validate import validate_plan

SMALL_LIBERO = [
    "libero_10/KITCHEN_SCENE4_put_the_black_bowl_in_the_bottom_drawer_of_the_cabinet_and_close_it.bddl",
    "libero_goal/open_the_top_drawer_and_put_the_bowl_inside.bddl",
    "libero_10/LIVING_ROOM_SCENE2_put_both_the_alphabet_soup_and_the_tomato_sauce_in_the_basket.bddl",
    "libero_spatial/pick_up_the_black_bowl_in_the_top_drawer_of_the_wooden_cabinet_and_place_it_on_the_plate.bddl",
]


@functools.cache
def _tabletop():
    return load_builtin_domain("tabletop")


def _libero(libero_dir: Path, name: str):
    from gsr.libero import libero_task
    from gsr.pddl.bddl import load_bddl

    domain = _tabletop()
    return domain, libero_task(load_bddl(libero_dir / name), domain)[1]


def test_all_libero_tasks_plan_and_validate(libero_dir: Path) -> None:
    files = sorted(libero_dir.rglob("*.bddl"))
    assert len(files) == 40
    for bddl in files:
        domain, problem = _libero(libero_dir, str(bddl.relative_to(libero_dir)))
        result = plan(domain, problem, timeout=30)
        assert result.status == "solved", (bddl.name, result.message)
        assert validate_plan(domain, problem, result.plan).valid, bddl.name


@pytest.mark.parametrize("name", SMALL_LIBERO)
def test_libero_optimal_cost_matches_bfs_and_fast_downward(
    libero_dir: Path, name: str, tmp_path: Path
) -> None:
    domain, problem = _libero(libero_dir, name)
    costs = {
        p: plan(domain, problem, planner=p, timeout=30).cost for p in ("astar-lmcut", "astar-hmax", "bfs")
    }
    assert len(set(costs.values())) == 1, costs
    if find_fast_downward() is None:
        pytest.skip("Fast Downward (up-fast-downward) is not installed")
    from gsr.pddl.writer import write_domain, write_problem

    (tmp_path / "d.pddl").write_text(write_domain(domain))
    (tmp_path / "p.pddl").write_text(write_problem(problem))
    # The tabletop domain has conditional effects and quantified negative preconditions (FD: axioms),
    # which FD's LM-cut rejects; blind A* is optimal too.
    status, fd_plan, message = run_fast_downward(
        tmp_path / "d.pddl", tmp_path / "p.pddl", 60, search="astar(blind())"
    )
    assert status == "solved", message
    assert costs["astar-lmcut"] == len(fd_plan)


def test_plan_graph_on_a_gsr_bench_scene() -> None:
    message = {
        "nodes": ["table", "short_cabinet", "short_cabinet/drawer_high(open)", "short_cabinet/drawer_low(closed)",
                  "red_cube1", "red_cube2", "blue_box"],
        "edges": ["short_cabinet(on)table", "red_cube1(on)table", "red_cube2(in)blue_box", "blue_box(on)table"],
    }  # fmt: skip
    graph = graph_from_gsr_bench(message)
    drawer = "short_cabinet/drawer_low"
    goal = Goal(
        And(
            (
                Atom("in", ("red_cube1", drawer)),
                Atom("in", ("red_cube2", drawer)),
                Not(Atom("open", (drawer,))),
            )
        )
    )
    result = plan_graph(None, graph, goal)
    assert result.status == "solved", result.message
    problem = problem_from_graph(graph, goal.formula, domain=_tabletop())
    assert validate_plan(_tabletop(), problem, result.plan).valid
    actions = [str(s) for s in result.plan]
    # The high drawer must be closed before the low one is reachable, and the low one closed at the end.
    assert actions.index("(close short_cabinet/drawer_high)") < actions.index(f"(open {drawer})")
    assert actions[-1] == f"(close {drawer})" and len(actions) == 7


def test_long_tabletop_generator_is_deterministic_and_long() -> None:
    first = long_tabletop_tasks(4, seed=7)
    assert first == long_tabletop_tasks(4, seed=7)
    assert first != long_tabletop_tasks(4, seed=8)
    assert len({name for name, _, _ in first}) == 4
    for seed in range(12):
        _, graph, goal, lower_bound = long_tabletop_task(seed)
        assert lower_bound >= 10
        assert graph.has_node("short_cabinet/drawer_low") and isinstance(goal, And)


@pytest.mark.parametrize("seed", [0, 1, 5])
def test_long_tabletop_tasks_plan_and_validate(seed: int) -> None:
    name, graph, goal, lower_bound = long_tabletop_task(seed)
    domain = _tabletop()
    problem = problem_from_graph(graph, goal, name=name, domain=domain)
    result = plan(domain, problem, timeout=60)
    assert result.status == "solved", result.message
    assert len(result.plan) >= lower_bound
    assert validate_plan(domain, problem, result.plan).valid


def test_incremental_hadd_equals_counting_from_scratch_and_the_heap_version(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # h_add starts from the initial state's level 0 adjusted for the differing atoms; its costs must
    # equal the heap version's, and its supporters (so h_FF and the preferred operators) must equal
    # counting every fact down from scratch. All in Python: on a loaded machine the Python h_FF
    # passes the compiled path's time switch mid-test (flaky before).
    monkeypatch.setenv("GSR_PLAN_JIT", "0")
    name, graph, goal, _ = long_tabletop_task(3)
    domain = _tabletop()
    task = ground_task(domain, problem_from_graph(graph, goal, name=name, domain=domain))
    relax, scratch, heap = Relaxation(task), Relaxation(task), Relaxation(task)
    scratch.far = 10**9  # every state differing from the initial one is counted from scratch
    heap.integral = False  # the binary-heap h_add (its own instance: hadd remembers its last state)
    result = plan(domain, problem_from_graph(graph, goal, name=name, domain=domain))
    index = {(o.name, o.args): i for i, o in enumerate(task.ops)}
    states = [task.init]
    for step in result.plan:
        states.append(task.apply(states[-1], index[(step.action, step.args)]))
    states += [task.apply(s, op) for s in states[:6] for op in task.applicable(s)]
    assert len(states) > 40
    for state in states:
        assert relax.ff(state) == scratch.ff(state)
        # Both stop once G is settled, so only the goal's cost is comparable.
        assert heap.hadd(state)[0][heap.goal_fact] == relax.hadd(state)[0][relax.goal_fact]
        # The remembered last result is the one computed afresh.
        assert relax.hadd(state) is relax.hadd(state)
        assert relax.hadd(state) == scratch._hadd_buckets(state)


def test_domain_tables_are_reused_per_domain_object_and_match_a_fresh_parse() -> None:
    # ground_task compiles the domain-only tables (normalised schemas, effect groups) once per
    # domain object; a freshly parsed copy of the domain must ground to the very same task.
    from gsr.plan.grounding import grounding_tables
    from gsr.resources import domain_path

    domain = _tabletop()
    assert grounding_tables(domain) is grounding_tables(domain)
    fresh = parse_domain(domain_path("tabletop").read_text())
    assert fresh is not domain and grounding_tables(fresh) is not grounding_tables(domain)
    for seed in (2, 4):
        name, graph, goal, _ = long_tabletop_task(seed)
        problem = problem_from_graph(graph, goal, name=name, domain=domain)
        cached, again, parsed = (
            ground_task(domain, problem),
            ground_task(domain, problem),
            ground_task(fresh, problem),
        )
        for task in (again, parsed):
            assert task.atoms == cached.atoms and task.ops == cached.ops
            assert task.init == cached.init and task.goals == cached.goals
        assert len(cached.ops) > 100


def test_relaxation_counts_negative_goals_and_preconditions() -> None:
    # Removing the blocker from the lid (a negated quantified precondition of open) is invisible to a
    # relaxation that drops negative literals (h_FF would be 3); complement facts make h_FF count it.
    graph = graph_from_gsr_bench(
        {"nodes": ["table", "red_lidded_box(closed)", "blue_box", "red_cube1"],
         "edges": ["red_lidded_box(on)table", "blue_box(on)red_lidded_box", "red_cube1(on)table"]}
    )  # fmt: skip
    goal = And((Atom("in", ("red_cube1", "red_lidded_box")), Not(Atom("open", ("red_lidded_box",)))))
    domain = _tabletop()
    task = ground_task(domain, problem_from_graph(graph, goal, domain=domain))
    h, preferred = Relaxation(task).ff(task.init)
    # Relaxed plan: pick blue_box (achieves "blue_box not on the lid"), open, pick the cube, place it in.
    assert h == 4
    assert sorted(str(task.ops[o]) for o in preferred) == [
        "(pick blue_box red_lidded_box)",
        "(pick red_cube1 table)",
    ]
    # The real plan also puts blue_box down and closes the lid again: 6 actions.
    result = plan(domain, problem_from_graph(graph, goal, domain=domain), planner="astar-lmcut")
    assert result.cost == 6


VAULT = """
(define (domain vault)
  (:requirements :strips :typing :negative-preconditions)
  (:types room)
  (:predicates (at ?r - room) (adj ?a ?b - room) (locked ?r - room) (key-in ?r - room) (has-key) (alarm))
  (:action move :parameters (?a ?b - room)
    :precondition (and (at ?a) (adj ?a ?b) (not (locked ?b)) (not (alarm)))
    :effect (and (at ?b) (not (at ?a))))
  (:action take :parameters (?r - room)
    :precondition (and (at ?r) (key-in ?r) (not (has-key)))
    :effect (and (has-key) (not (key-in ?r))))
  (:action unlock :parameters (?a ?b - room)
    :precondition (and (at ?a) (adj ?a ?b) (locked ?b) (has-key))
    :effect (and (not (locked ?b)) (not (has-key)) (alarm)))
  (:action silence :parameters () :precondition (alarm) :effect (not (alarm))))
"""


def _vault_problem(n: int) -> str:
    rooms = [f"r{i}" for i in range(n)]
    adj = " ".join(f"(adj {a} {b}) (adj {b} {a})" for a, b in itertools.pairwise(rooms))
    locked = " ".join(f"(locked {r})" for r in rooms[2::2])
    keys = " ".join(f"(key-in {r})" for r in rooms[1::2])
    return f"""(define (problem v{n}) (:domain vault) (:objects {" ".join(rooms)} - room)
      (:init (at r0) {adj} {locked} {keys})
      (:goal (and (at {rooms[-1]}) (not (alarm)) (not (has-key)))))"""


@pytest.mark.parametrize("n", [3, 5, 7])
def test_negative_preconditions_optimal_cost_matches_fast_downward_lmcut(n: int, tmp_path: Path) -> None:
    domain = parse_domain(VAULT)
    problem = parse_problem(_vault_problem(n), domain=domain)
    results = {p: plan(domain, problem, planner=p, timeout=30) for p in ("astar-lmcut", "astar-hmax", "bfs")}
    assert {r.status for r in results.values()} == {"solved"}
    assert len({r.cost for r in results.values()}) == 1, {p: r.cost for p, r in results.items()}
    assert validate_plan(domain, problem, results["astar-lmcut"].plan).valid
    if find_fast_downward() is None:
        pytest.skip("Fast Downward (up-fast-downward) is not installed")
    (tmp_path / "d.pddl").write_text(VAULT)
    (tmp_path / "p.pddl").write_text(_vault_problem(n))
    status, fd_plan, message = run_fast_downward(
        tmp_path / "d.pddl", tmp_path / "p.pddl", 60, search="astar(lmcut())"
    )
    assert status == "solved", message
    assert results["astar-lmcut"].cost == len(fd_plan)


def test_fast_simplifier_equals_reference_ground_simplify(libero_dir: Path) -> None:
    from gsr.pddl.walk import to_dnf
    from gsr.plan.grounding import ObjectsByType
    from gsr.plan.grounding.normalize import ground_simplify, normalize_action
    from gsr.plan.grounding.simplify import Simplifier

    domain = _tabletop()
    _, graph, goal, _ = long_tabletop_task(3)
    scenes = [problem_from_graph(graph, goal, domain=domain), _libero(libero_dir, SMALL_LIBERO[3])[1]]
    schemas = [normalize_action(a) for a in domain.actions.values()]
    fluent = {e.literal.atom.predicate for s in schemas for e in s.effects}
    checked = 0
    for problem in scenes:
        objects = ObjectsByType(domain, problem.all_objects(domain))
        fast = Simplifier(objects, fluent, problem.init)

        def static(atom: Atom, init=problem.init) -> bool | None:
            return None if atom.predicate in fluent else atom in init

        for schema in schemas:
            params = schema.all_params
            combos = itertools.islice(itertools.product(*(objects(p.types) for p in params)), 150)
            for combo in combos:
                binding = dict(zip((p.name for p in params), combo, strict=True))
                formula = And((*schema.join, schema.residual))
                expected = set(to_dnf(ground_simplify(formula, binding, objects, static)))
                assert set(to_dnf(fast(formula, binding))) == expected, (schema.name, binding)
                for eff in schema.effects:
                    # Guarded enumeration must find exactly the instances whose condition can hold.
                    got, want = set(), set()
                    for b in fast.instances(eff.params, fast.guards(eff.condition, True), binding):
                        lits = fast.literals(eff.condition)
                        conds = (
                            [fast.ground_literals(lits, b)]
                            if lits is not None
                            else to_dnf(fast(eff.condition, b))
                        )
                        got |= {(tuple(sorted(b.items())), c) for c in conds if c is not None}
                    for extra in itertools.product(*(objects(v.types) for v in eff.params)):
                        b = {**binding, **dict(zip((v.name for v in eff.params), extra, strict=True))}
                        conds = to_dnf(ground_simplify(eff.condition, b, objects, static))
                        want |= {(tuple(sorted(b.items())), c) for c in conds}
                    assert got == want, (schema.name, binding, eff.literal)
                checked += 1
    assert checked > 500
