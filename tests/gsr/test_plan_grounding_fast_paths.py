"""The grounder's and h_add's fast paths give exactly what the general paths give."""

from __future__ import annotations

import functools
import random

from gsr.benchmarks.bench_planner import long_tabletop_task

from gsr.facts import problem_from_graph
from gsr.plan import plan
from gsr.plan.ground import ObjectsByType, ground_task, grounding_tables, schema_bindings
from gsr.plan.heuristics import Relaxation
from gsr.plan.precondition import fast_dnf, id_dnf, relaxed, relaxed_core
from gsr.plan.simplify import Simplifier
from gsr.resources import load_builtin_domain
from gsr.validate import validate_plan


@functools.cache
def _tabletop():
    return load_builtin_domain("tabletop")


def _problem(seed: int):
    name, graph, goal, _ = long_tabletop_task(seed)
    return problem_from_graph(graph, goal, name=name, domain=_tabletop())


def _ground_preconditions(seed: int):
    """Every candidate action's simplified precondition (the fixpoint's inputs), with the problem."""
    domain, problem = _tabletop(), _problem(seed)
    compiled = grounding_tables(domain)
    objects = ObjectsByType(domain, problem.all_objects(domain))
    simplify = Simplifier(objects, compiled.fluent, problem.init)
    index: dict[str, set[tuple[str, ...]]] = {}
    for a in problem.init:
        index.setdefault(a.predicate, set()).add(a.args)
    out = []
    for schema in compiled.schemas:
        for binding in schema_bindings(schema, index, objects)[:40]:
            pre = simplify(schema.residual, binding)
            out.append(pre)
    return problem, out


def test_relaxed_core_decides_like_the_formula_on_random_reached_sets() -> None:
    problem, pres = _ground_preconditions(1)
    atoms = sorted({(a.predicate, a.args) for a in problem.init} | {("open", (o,)) for o in problem.objects})
    rng = random.Random(0)
    cache: dict = {}
    checked = 0
    for pre in pres:
        core = relaxed_core(pre, cache)
        for _ in range(5):
            reached = {a for a in atoms if rng.random() < 0.7}
            assert relaxed(core, reached) == relaxed(pre, reached)
            checked += 1
    assert checked > 100


def test_fast_dnf_equals_the_general_dnf_over_ids() -> None:
    problem, pres = _ground_preconditions(2)
    task = ground_task(_tabletop(), problem)
    reached = set(task.atoms) | set(problem.init)
    keys = {(a.predicate, a.args): i for i, a in enumerate(task.atoms)}
    cache: dict = {}
    compared = 0
    for pre in pres:
        fast = fast_dnf(pre, keys, cache)
        if fast is None:
            continue
        assert sorted(map(sorted, fast)) == sorted(map(sorted, id_dnf(pre, reached, keys)))
        compared += 1
    assert compared > 50


def test_disjunction_join_lists_exactly_the_bindings_the_filter_keeps() -> None:
    # pick's (or (on ?o ?from) (in ?o ?from)) is joined while listing bindings; without the join
    # every ?from is listed and the disjunction tested afterwards.
    domain, problem = _tabletop(), _problem(3)
    compiled = grounding_tables(domain)
    objects = ObjectsByType(domain, problem.all_objects(domain))
    index: dict[str, set[tuple[str, ...]]] = {}
    for a in problem.init:
        index.setdefault(a.predicate, set()).add(a.args)
    si = [s.name for s in compiled.schemas].index("pick")
    schema, disjunction = compiled.schemas[si], compiled.disjunctions[si]
    assert [a.predicate for a in disjunction] == ["on", "in"]

    def holds(b: dict[str, str]) -> bool:
        return any(
            a.predicate in index and tuple(b[x] for x in a.args) in index[a.predicate] for a in disjunction
        )

    def key(b: dict[str, str]) -> tuple[str, ...]:
        return tuple(b[p.name] for p in schema.all_params)

    joined = sorted(map(key, schema_bindings(schema, index, objects, disjunction)))
    filtered = sorted(key(b) for b in schema_bindings(schema, index, objects) if holds(b))
    assert joined == filtered and len(joined) >= 5


def test_hadd_stopping_at_the_goal_operator_keeps_h_ff_and_preferred_operators() -> None:
    problem = _problem(5)
    task = ground_task(_tabletop(), problem)
    early, full = Relaxation(task), Relaxation(task)
    assert early.goal_stop == early.goal_fact  # one goal disjunct
    full.goal_stop = -1  # settle every fact cheaper than the goal, as before the early stop
    result = plan(_tabletop(), problem)
    assert result.solved and validate_plan(_tabletop(), problem, result.plan).valid
    index = {(o.name, o.args): i for i, o in enumerate(task.ops)}
    states = [task.init]
    for step in result.plan:
        states.append(task.apply(states[-1], index[(step.action, step.args)]))
    for state in states:
        e_cost, _ = early.hadd(state)
        f_cost, _ = full.hadd(state)
        assert e_cost[early.goal_fact] == f_cost[full.goal_fact]
        assert early.ff(state) == full.ff(state)
