"""Plan validation: agreement with unified-planning's validator on random plans, ADL plans, IPC plan files."""

from __future__ import annotations

import itertools
import random
from pathlib import Path

import pytest

from gsr.diagnosis import ReasonKind
from gsr.errors import GSRError, ParseError
from gsr.pddl.parser import load_domain, load_problem
from gsr.plan_format import load_plan, parse_plan, write_plan
from gsr.semantics import applicable, apply
from gsr.state import initial_state
from gsr.step import Plan, Step
from gsr.validate import validate_plan
from tests.data_paths import PDDL

ORACLE_PROBLEMS = [
    ("blocks", "probBLOCKS-4-0.pddl"),
    ("blocks", "probBLOCKS-4-1.pddl"),
    ("blocks", "probBLOCKS-4-2.pddl"),
    ("blocks", "probBLOCKS-5-0.pddl"),
    ("gripper", "prob01.pddl"),
]


def _ground_actions(domain, state):
    objects = list(state.objects)
    for name, action in domain.actions.items():
        for args in itertools.product(objects, repeat=len(action.params)):
            yield Step(name, args)


def _bfs_plan(domain, problem, limit: int = 20000) -> list[Step]:
    """A shortest plan by breadth-first search (small problems only)."""
    from gsr.semantics import goal_holds

    start = initial_state(domain, problem)
    frontier = [(start, [])]
    seen = {start.atoms}
    while frontier and len(seen) < limit:
        nxt = []
        for state, plan in frontier:
            if goal_holds(domain, problem.goal, state):
                return plan
            for step in _ground_actions(domain, state):
                if applicable(domain, state, step.action, step.args):
                    succ = apply(domain, state, step.action, step.args)
                    if succ.atoms not in seen:
                        seen.add(succ.atoms)
                        nxt.append((succ, [*plan, step]))
        frontier = nxt
    raise AssertionError("no plan found")


def _random_plans(domain, problem, rng: random.Random, count: int) -> list[list[Step]]:
    """Random walks over applicable steps, goal plans and mutated variants of both."""
    solution = _bfs_plan(domain, problem)
    objects = list(initial_state(domain, problem).objects)
    plans = []
    for i in range(count):
        kind = i % 6
        if kind in (0, 1):  # random walk of applicable steps
            state, plan = initial_state(domain, problem), []
            for _ in range(rng.randint(0, 12)):
                options = [
                    s for s in _ground_actions(domain, state) if applicable(domain, state, s.action, s.args)
                ]
                step = rng.choice(options)
                plan.append(step)
                state = apply(domain, state, step.action, step.args)
        elif kind == 2:  # the solution itself, or with a random suffix of applicable steps
            plan = list(solution)
        elif kind == 3:  # truncated solution: applicable but misses the goal
            plan = solution[: rng.randint(0, len(solution) - 1)]
        else:
            plan = list(solution)
        if kind in (1, 4) and plan:  # wrong arguments in one step
            j = rng.randrange(len(plan))
            step = plan[j]
            args = list(step.args)
            if args:
                args[rng.randrange(len(args))] = rng.choice(objects)
            plan[j] = Step(step.action, tuple(args))
        if kind == 5:  # a step inserted or two swapped
            if rng.random() < 0.5 or len(plan) < 2:
                plan.insert(
                    rng.randint(0, len(plan)),
                    rng.choice(list(_ground_actions(domain, initial_state(domain, problem)))),
                )
            else:
                a, b = rng.sample(range(len(plan)), 2)
                plan[a], plan[b] = plan[b], plan[a]
        plans.append(plan)
    return plans


def test_agrees_with_unified_planning_on_random_plans() -> None:
    pytest.importorskip("unified_planning")
    from unified_planning.engines.plan_validator import SequentialPlanValidator
    from unified_planning.engines.results import FailedValidationReason, ValidationResultStatus
    from unified_planning.io import PDDLReader
    from unified_planning.shortcuts import get_environment

    get_environment().credits_stream = None
    rng = random.Random(7)
    oracle = SequentialPlanValidator()
    checked = valid = goal_misses = inapplicable = 0
    for folder, name in ORACLE_PROBLEMS:
        domain = load_domain(PDDL / folder / "domain.pddl")
        problem = load_problem(PDDL / folder / name, domain)
        reader = PDDLReader()
        up_problem = reader.parse_problem(str(PDDL / folder / "domain.pddl"), str(PDDL / folder / name))
        for steps in _random_plans(domain, problem, rng, 104):
            text = write_plan(Plan(tuple(steps)))
            ours = validate_plan(domain, problem, parse_plan(text))
            theirs = oracle.validate(up_problem, reader.parse_plan_string(up_problem, text))
            context = f"{folder}/{name}:\n{text}\nours: {ours.message}\nup: {theirs.status} {theirs.reason}"
            assert ours.valid == (theirs.status == ValidationResultStatus.VALID), context
            if theirs.reason == FailedValidationReason.INAPPLICABLE_ACTION:
                assert ours.failed_step == len(theirs.trace) - 1, context
                inapplicable += 1
            elif theirs.reason == FailedValidationReason.UNSATISFIED_GOALS:
                assert ours.failed_step is None and not ours.goal_reached, context
                goal_misses += 1
            else:
                assert ours.goal_reached and ours.failed_step is None, context
                valid += 1
            checked += 1
    assert checked >= 500
    # The generator must exercise every verdict, or agreement would mean little.
    assert valid >= 50 and goal_misses >= 50 and inapplicable >= 50, (valid, goal_misses, inapplicable)


# ------------------------------------------------------------ ADL: miconic (forall + when effects)


@pytest.fixture(scope="module")
def miconic():
    domain = load_domain(PDDL / "miconic-simpleadl" / "domain.pddl")
    return domain, load_problem(PDDL / "miconic-simpleadl" / "s1-0.pddl", domain)


def test_miconic_valid_plan(miconic) -> None:
    domain, problem = miconic
    report = validate_plan(domain, problem, parse_plan("(up f0 f1)\n(stop f1)\n(down f1 f0)\n(stop f0)\n"))
    assert report.valid and report.goal_reached and report.cost == 4
    boarded = report.steps[1].next_state
    assert ("boarded", ("p0",)) in {(a.predicate, a.args) for a in boarded.atoms}
    assert report.final_state.atoms >= {a for a in report.final_state.atoms if a.predicate == "served"}
    assert any(a.predicate == "served" for a in report.final_state.atoms)
    assert not any(a.predicate == "boarded" for a in report.final_state.atoms)


def test_miconic_invalid_plan_reports_step_and_goal(miconic) -> None:
    domain, problem = miconic
    report = validate_plan(domain, problem, parse_plan("(up f0 f1)\n(stop f1)\n(stop f0)\n(down f1 f0)\n"))
    assert not report.valid and report.failed_step == 2
    failure = report.failure
    assert failure is not None and failure.reasons[0].kind is ReasonKind.UNSATISFIED_PRECONDITION
    assert failure.reasons[0].literal == "(lift-at f0)"
    assert "(down f1 f0) first" in failure.hints[0]
    assert [r.kind for r in report.goal_reasons] == [ReasonKind.GOAL_UNSATISFIED]
    assert report.goal_reasons[0].literal == "(served p0)"
    text = str(report)
    assert "step 3" in text and "ERR (stop f0)" in text and "1 later step(s) not checked" in text
    assert report.to_dict()["failed_step"] == 2


def test_stop_without_passengers_changes_nothing(miconic) -> None:
    domain, problem = miconic
    report = validate_plan(domain, problem, parse_plan("(stop f0)"))
    assert report.failed_step is None and not report.goal_reached
    assert report.final_state.atoms == initial_state(domain, problem).atoms


def test_goal_only_missing(miconic) -> None:
    domain, problem = miconic
    report = validate_plan(domain, problem, Plan(()))
    assert not report.valid and report.failed_step is None
    assert report.message.startswith("plan invalid: all 0 step(s) apply but goal (served p0) is false")
    # p0 has not boarded, so no stop serves it now: the hint names the achiever without a false promise
    assert report.goal_hints == ("(stop ?f) adds (served p0), but its preconditions do not hold yet",)


# ------------------------------------------------------------ IPC plan format


def test_parse_plan_comments_case_timestamps() -> None:
    text = "; a plan\n\n0: (PICK-UP B)  ; first\n1.5: (stack b a) [1]\n(Put-Down short_cabinet/drawer_low)\n; cost = 3 (unit cost)\n"
    plan = parse_plan(text)
    assert [str(s) for s in plan] == ["(pick-up b)", "(stack b a)", "(put-down short_cabinet/drawer_low)"]
    assert (
        write_plan(plan)
        == "(pick-up b)\n(stack b a)\n(put-down short_cabinet/drawer_low)\n; cost = 3 (unit cost)\n"
    )
    assert parse_plan(write_plan(plan)) == plan
    assert write_plan(plan, cost=7.5).endswith("; cost = 7.5 (general cost)\n")


@pytest.mark.parametrize(
    ("text", "line", "column"),
    [
        ("(pick-up a)\n(stack a b", 2, 11),
        ("(pick-up a))", 1, 12),
        ("pick-up a", 1, 1),
        ("(pick-up a)\n\n  ()", 3, 4),
        ("(pick-up a)\n3: ", 2, 4),
        ("(pick-up a (b))", 1, 12),
    ],
)
def test_parse_plan_errors_have_positions(text: str, line: int, column: int) -> None:
    with pytest.raises(ParseError) as err:
        parse_plan(text, source="p.plan")
    assert (err.value.line, err.value.column) == (line, column)
    assert str(err.value).startswith(f"p.plan:{line}:{column}:")


def test_load_plan(tmp_path: Path) -> None:
    path = tmp_path / "sas_plan"
    path.write_text("(pick-up a)\n; cost = 1 (unit cost)\n")
    assert load_plan(path) == Plan((Step("pick-up", ("a",)),))
    with pytest.raises(GSRError, match="cannot read plan file"):
        load_plan(tmp_path / "missing")
    (tmp_path / "binary").write_bytes(b"\xff\xfe(pick-up a)")
    with pytest.raises(GSRError, match="not UTF-8 text"):
        load_plan(tmp_path / "binary")
