"""The grounder's and h_add's fast paths give exactly what the general paths give."""

from __future__ import annotations

import copy
import functools
import random

from gsr.benchmarks.bench_planner import long_tabletop_task

from gsr.facts import problem_from_graph
from gsr.pddl.model import TRUE, And, Atom, Not, Or
from gsr.plan import plan
from gsr.plan.grounding import ObjectsByType, ground_task, grounding_tables, schema_bindings
from gsr.plan.grounding.effects import Variant
from gsr.plan.grounding.intern import precondition_dnf
from gsr.plan.grounding.precondition import fast_dnf, id_dnf, relaxed, relaxed_core
from gsr.plan.grounding.simplify import Simplifier
from gsr.plan.heuristics import Relaxation
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


def _with_literals_from_compounds(pres: list, reachable: set, rng: random.Random) -> list:
    """The preconditions, and each one with a compound conjunct again with a literal of an atom
    inside that conjunct (a reachable one), of each sign (disjuncts it contradicts, or that come to
    subsume others)."""
    out = list(pres)
    for pre in pres:
        parts = pre.parts if isinstance(pre, And) else (pre,)
        inner = [a for p in parts if isinstance(p, (And, Or)) for a in _atoms(p) if a in reachable]
        if inner:
            atom = rng.choice(inner)
            out += [And((*parts, atom)), And((*parts, Not(atom)))]
    return out


def _atoms(formula) -> list:
    if isinstance(formula, Atom):
        return [formula]
    if isinstance(formula, Not):
        return _atoms(formula.formula)
    return [a for p in getattr(formula, "parts", ()) for a in _atoms(p)]


def test_precondition_dnf_from_literal_keys_equals_the_general_dnf() -> None:
    # A Variant keeps its fluent literals as keys and only the other conjuncts as formulas; its
    # DNF over ids must be that of the whole precondition, also with atoms left unreached.
    problem, pres = _ground_preconditions(4)
    task = ground_task(_tabletop(), problem)
    rng = random.Random(1)
    compared = merged = 0
    for keep in (1.0, 0.8):
        atoms = [a for a in task.atoms if rng.random() < keep]
        keys = {(a.predicate, a.args): i for i, a in enumerate(atoms)}
        reached = set(atoms)
        cache: dict = {}
        for pre in _with_literals_from_compounds(pres, set(task.atoms), rng):
            parts = pre.parts if isinstance(pre, And) else () if pre is TRUE else (pre,)
            pos = tuple((p.predicate, p.args) for p in parts if isinstance(p, Atom))
            neg = tuple(
                (p.formula.predicate, p.formula.args)
                for p in parts
                if isinstance(p, Not) and isinstance(p.formula, Atom)
            )
            compound = tuple(p for p in parts if not isinstance(p, (Atom, Not)))
            v = Variant("a", (), {}, None, pos, neg, compound, ())  # type: ignore[arg-type]
            fast = precondition_dnf(v, keys, cache)
            if fast is None:
                continue
            assert sorted(map(sorted, fast)) == sorted(map(sorted, id_dnf(pre, reached, keys)))
            compared += 1
            merged += bool(compound and (pos or neg))
    assert compared > 100 and merged > 20


def test_split_disjunctions_ground_the_same_task(monkeypatch) -> None:
    # Disjunctions over all of an action's variables are split into groups over fewer variables
    # (pick's (imply (in ?o ?from) ...)); grounding without the split gives the very same task.
    # (A copy of the domain is a new identity, so its grounding tables are compiled afresh.)
    import gsr.plan.grounding.fixpoint as ground

    domain = copy.copy(_tabletop())
    tables = ground.grounding_tables(domain)
    names = [{p.name for p in s.all_params} for s in tables.schemas]
    split = [
        part
        for parts, n in zip(tables.parts, names, strict=True)
        for part, _, _ in parts
        if ground.or_split(part, n)
    ]
    assert len(split) >= 3
    tasks = [ground_task(domain, _problem(seed)) for seed in (6, 7, 8)]
    monkeypatch.setattr(ground, "or_split", lambda part, params: None)
    plain_domain = copy.copy(_tabletop())
    for seed, task in zip((6, 7, 8), tasks, strict=True):
        plain = ground_task(plain_domain, _problem(seed))
        assert (plain.atoms, plain.ops, plain.init, plain.goals) == (
            task.atoms,
            task.ops,
            task.init,
            task.goals,
        )


def test_precondition_dnf_drops_disjuncts_the_literals_contradict_or_make_redundant() -> None:
    a, b, c = Atom("p", ("a",)), Atom("p", ("b",)), Atom("p", ("c",))
    keys = {("p", ("a",)): 0, ("p", ("b",)): 1, ("p", ("c",)): 2}
    either = Or((a, And((b, c))))
    # (a or (b and c)) and a: {a} alone; the other disjunct, now {a, b, c}, is subsumed by it.
    v = Variant("x", (), {}, None, (("p", ("a",)),), (), (either,), ())  # type: ignore[arg-type]
    assert precondition_dnf(v, keys, {}) == [frozenset({0})]
    # (a or (b and c)) and not a: only {b, c, not a}.
    v = Variant("x", (), {}, None, (), (("p", ("a",)),), (either,), ())  # type: ignore[arg-type]
    assert precondition_dnf(v, keys, {}) == [frozenset({1, 2, ~0})]
