"""The step checker: is a proposed step valid in a state, and if not, why and how to repair it.

``check_step`` has a fast path (compiled precondition and effects, see gsr.semantics) that
answers valid steps in a few microseconds; only an invalid step pays for the explanation
(gsr.diagnosis.Explainer) and the repair hints. Hints are domain-driven: for a false literal
``(p a b)`` the actions whose effects add ``p`` (or delete it, for ``(not (p a b))``) are
unified with the literal, their remaining parameters searched for a binding whose precondition
holds now, and the first such ground action is proposed.
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping

from gsr.diagnosis import (
    Diagnosis,
    Explainer,
    Failure,
    Reason,
    ReasonKind,
    fact_text,
    formula_text,
)
from gsr.pddl.model import Atom, Domain, Literal, is_variable
from gsr.pddl.walk import effect_literals
from gsr.semantics import CompiledAction, CompiledDomain, Fact, atom_fact, compile_domain
from gsr.state import State
from gsr.step import Step

MAX_HINTS = 4
_MEMO_LIMIT = 20_000  # memo entries per state before it is cleared
_SEARCH_BUDGET = 100  # precondition evaluations per achiever when grounding a hint
# Partial bindings visited per achiever: dead ends never reach a precondition evaluation, so they
# need their own bound (tetris' 7-parameter moves over 40 cells took minutes without it).
_NODE_BUDGET = 50 * _SEARCH_BUDGET
_NO_NUMERIC: dict = {}


# ------------------------------------------------------------ hints


_ACHIEVERS: dict[int, tuple[CompiledDomain, dict]] = {}


def _static_hint(cd: CompiledDomain, state: State, failure: Failure, exclude: Step | None) -> str:
    """For a literal over a predicate no action changes: say so, and which objects do satisfy it."""
    fact = failure.fact
    assert fact is not None
    pred = fact[0]
    if not failure.wanted:
        return f"{fact_text(fact)} always holds here (no action changes {pred}): use other objects"
    args = exclude.args if exclude is not None else ()
    j = next((j for j in range(1, len(fact)) if fact[j] in args), 1)
    sample: list[str] = []
    if len(fact) > 1:
        for f in cd.view(state)[3].get((pred,), ()):
            fits = len(f) == len(fact) and all(f[k] == fact[k] for k in range(1, len(fact)) if k != j)
            if fits and f[j] not in sample:
                sample.append(f[j])
    where = f"; it holds for {', '.join(sample[:5])}{', ...' if len(sample) > 5 else ''}" if sample else ""
    return f"{fact_text(fact)} can never become true (no action changes {pred}){where}"


def _achiever_index(cd: CompiledDomain) -> dict[tuple[str, bool], list[tuple[CompiledAction, Literal]]]:
    hit = _ACHIEVERS.get(id(cd))
    if hit is not None and hit[0] is cd:
        return hit[1]
    index: dict[tuple[str, bool], list[tuple[CompiledAction, Literal]]] = {}
    for ca in cd.actions.values():
        for lit in effect_literals(ca.action.effect):
            index.setdefault((lit.atom.predicate, not lit.negated), []).append((ca, lit))
    _ACHIEVERS[id(cd)] = (cd, index)
    return index


def _unify(ca: CompiledAction, lit: Literal, fact: Fact) -> dict[str, str] | None:
    """Bind the action's parameters so that ``lit`` is ``fact``; None when impossible."""
    if len(lit.atom.args) != len(fact) - 1:
        return None
    params = {p.name for p in ca.action.params}
    binding: dict[str, str] = {}
    for term, value in zip(lit.atom.args, fact[1:], strict=True):
        if not is_variable(term):
            if term != value:
                return None
        elif term in params and binding.setdefault(term, value) != value:
            return None  # (a forall-effect variable ranges over everything: no constraint)
    return binding


class _Grounder:
    """Finds a binding of an action's free parameters under which its precondition holds now."""

    def __init__(self, cd: CompiledDomain, state: State) -> None:
        self.cd = cd
        self.state = state
        self.view = cd.view(state)

    def candidates(self, ca: CompiledAction, var: str, binding: dict[str, str], objects: list) -> list[str]:
        """Objects for ``var``: narrowed through the fact index by a positive precondition atom."""
        i = [p.name for p in ca.action.params].index(var)
        typed = objects[ca.param_slots[i]]
        allowed = self.view[2][ca.param_slots[i]]
        for conj, _ in ca.conjuncts:
            if not isinstance(conj, Atom) or var not in conj.args:
                continue
            pattern = [binding.get(t, t) for t in conj.args]
            if any(is_variable(t) and t != var for t in pattern):
                continue
            bound = [(j, v) for j, v in enumerate(pattern, 1) if v != var]
            key = (conj.predicate, *bound[0]) if bound else (conj.predicate,)
            spots = [j for j, v in enumerate(pattern, 1) if v == var]
            found = {
                f[spots[0]]
                for f in self.view[3].get(key, ())
                if len(f) == len(pattern) + 1
                and all(f[j] == v for j, v in bound)
                and all(f[j] == f[spots[0]] for j in spots)
            }
            return [o for o in typed if o in found] if len(found) < len(allowed) else list(typed)
        return list(typed)

    def produces(
        self, ca: CompiledAction, args: tuple[str, ...], fact: Fact, wanted: bool, objects: list
    ) -> bool:
        """True when ``ca(args)`` really adds (deletes) ``fact`` now: ``when`` conditions are evaluated."""
        adds, dels, _ = ca.eff(*self.view, _NO_NUMERIC, *args)
        return fact in adds if wanted else (fact in dels and fact not in adds)

    def ground(
        self, ca: CompiledAction, binding: dict[str, str], exclude: Step | None, fact: Fact, wanted: bool
    ) -> tuple[tuple[str, ...] | None, tuple[str, ...] | None]:
        """(first binding applicable now that produces the change, first producing one regardless)."""
        self.view = self.cd.view(self.state)
        objects = self.view[1]
        names = [p.name for p in ca.action.params]
        budget = [_SEARCH_BUDGET, _NODE_BUDGET]
        producing: list[tuple[str, ...]] = []

        def search(i: int, current: dict[str, str], narrow: bool) -> tuple[str, ...] | None:
            budget[1] -= 1
            if budget[1] <= 0:
                budget[0] = 0
                return None
            if i == len(names):
                args = tuple(current[n] for n in names)
                budget[0] -= 1
                if exclude is not None and exclude.action == ca.action.name and exclude.args == args:
                    return None
                if not self.produces(ca, args, fact, wanted, objects):
                    return None
                if ca.pre(*self.view, *args):
                    return args
                if not producing:
                    producing.append(args)
                return None
            name = names[i]
            if name in current:
                typed = objects[self.cd.type_slot(ca.param_types[i])]
                return search(i + 1, current, narrow) if current[name] in typed else None
            if narrow:
                values = self.candidates(ca, name, current, objects)
            else:
                values = list(objects[self.cd.type_slot(ca.param_types[i])])
            for value in values:
                if budget[0] <= 0:
                    return None
                found = search(i + 1, {**current, name: value}, narrow)
                if found is not None:
                    return found
            return None

        found = search(0, dict(binding), True)
        if found is None and not producing and budget[0] > 0:
            # Candidates were narrowed by preconditions that may be false: look for any producing binding.
            search(0, dict(binding), False)
        return found, (producing[0] if producing else None)

    def missing(self, ca: CompiledAction, binding: dict[str, str]) -> list[str]:
        """The false top-level preconditions of a fully bound action (PDDL text)."""
        names = [p.name for p in ca.action.params]
        if any(n not in binding for n in names):
            return []
        args = tuple(binding[n] for n in names)
        return [formula_text(conj, binding) for conj, fn in ca.conjuncts if not fn(*self.view, *args)]


def state_memo(cd: CompiledDomain, state: State) -> dict:
    """Per-state memo of explanations and hints (pure functions of the immutable state)."""
    cached = state.__dict__.get("_gsr_memo")
    if cached is None or cached[0] is not cd or len(cached[1]) > _MEMO_LIMIT:
        cached = (cd, {})
        state.__dict__["_gsr_memo"] = cached
    return cached[1]


def _achiever_hints(
    cd: CompiledDomain, state: State, failure: Failure, grounder: list
) -> tuple[list[tuple[str, tuple[str, ...], str]], str | None]:
    """Applicable ground achievers (name, args, hint) of a false literal, and a fallback hint."""
    assert failure.fact is not None
    verb = "adds" if failure.wanted else "deletes"
    found: list[tuple[str, tuple[str, ...], str]] = []
    fallback = None
    for ca, lit in _achiever_index(cd).get((failure.fact[0], failure.wanted), ()):
        binding = _unify(ca, lit, failure.fact)
        if binding is None:
            continue
        if not grounder:
            grounder.append(_Grounder(cd, state))
        args, producing = grounder[0].ground(ca, binding, None, failure.fact, failure.wanted)
        if args is not None:
            name = ca.action.name
            found.append(
                (name, args, f"({' '.join((name, *args))}) first (it {verb} {fact_text(failure.fact)})")
            )
            if len(found) == 3:
                break
        elif fallback is None:
            if producing is not None:
                binding = {p.name: a for p, a in zip(ca.action.params, producing, strict=True)}
            shown = " ".join(binding.get(p.name, p.name) for p in ca.action.params)
            needs = grounder[0].missing(ca, binding)
            why = (
                f"it needs {' and '.join(needs[:2])} first" if needs else "its preconditions do not hold yet"
            )
            fallback = f"({ca.action.name}{' ' + shown if shown else ''}) {verb} {fact_text(failure.fact)}, but {why}"
    return found, fallback


def repair_hints(
    cd: CompiledDomain, state: State, failures: list[Failure], exclude: Step | None = None
) -> list[str]:
    """Ground actions that would make the failed literals true (generic, from the domain's effects)."""
    index = _achiever_index(cd)
    memo = state_memo(cd, state)
    static = [
        f
        for f in failures
        if f.fact is not None and (f.fact[0], True) not in index and (f.fact[0], False) not in index
    ]
    if static:  # no earlier action can repair these: the step needs other arguments
        out = []
        for f in static[:MAX_HINTS]:
            key = ("static", f.fact, f.wanted, exclude.args if exclude is not None else ())
            if key not in memo:
                memo[key] = _static_hint(cd, state, f, exclude)
            out.append(memo[key])
        return list(dict.fromkeys(out))
    hints: list[str] = []
    grounder: list = []  # built on first need
    pending = list(failures)
    while pending and len(hints) < MAX_HINTS:
        failure = pending.pop(0)
        if failure.fact is None:
            pending[:0] = failure.children[:2]  # e.g. an `or`: try its first branches
            continue
        key = ("achievers", failure.fact, failure.wanted)
        if key not in memo:
            memo[key] = _achiever_hints(cd, state, failure, grounder)
        found, fallback = memo[key]
        usable = [
            text
            for name, args, text in found
            if exclude is None or (name, args) != (exclude.action, exclude.args)
        ][:2]
        if not usable and fallback is not None:
            usable = [fallback]
        hints.extend(h for h in usable if h not in hints)
    return hints[:MAX_HINTS]


# ------------------------------------------------------------ checker


def _close(word: str, choices: list[str], n: int = 3) -> list[str]:
    return difflib.get_close_matches(word, choices, n=n, cutoff=0.5)


def _fail(step: Step, reasons: list[Reason], hints: list[str]) -> Diagnosis:
    first = reasons[0].detail
    more = f" (+{len(reasons) - 1} more)" if len(reasons) > 1 else ""
    return Diagnosis(False, step, tuple(reasons), f"{step}: {first}{more}", tuple(hints))


def _check_signature(cd: CompiledDomain, state: State, step: Step) -> Diagnosis | None:
    """UNKNOWN_ACTION / WRONG_ARITY / UNKNOWN_OBJECT / TYPE_MISMATCH, or None when the call is well-formed."""
    ca = cd.actions.get(step.action)
    if ca is None:
        close = _close(step.action, sorted(cd.actions))
        hint = [f"did you mean {' or '.join(close)}?"] if close else []
        hint.append(f"known actions: {', '.join(sorted(cd.actions))}")
        reason = Reason(ReasonKind.UNKNOWN_ACTION, f"unknown action {step.action!r}")
        return _fail(step, [reason], hint)
    if len(step.args) != ca.arity:
        sig = f"({' '.join((step.action, *(p.name for p in ca.action.params)))})"
        detail = f"{step.action} takes {ca.arity} argument(s) {sig}, got {len(step.args)}"
        return _fail(step, [Reason(ReasonKind.WRONG_ARITY, detail)], [f"use the form {sig}"])
    reasons, hints = [], []
    objects = state.objects
    for i, (arg, param) in enumerate(zip(step.args, ca.action.params, strict=True)):
        kind = objects.get(arg)
        if kind is None:
            reasons.append(
                Reason(ReasonKind.UNKNOWN_OBJECT, f"unknown object {arg!r}", bindings=((param.name, arg),))
            )
            close = _close(arg, list(objects))
            if close:
                hints.append(f"did you mean {' or '.join(close)}?")
            else:
                fitting = [o for o, t in objects.items() if cd.is_subtype(t, ca.param_types[i])]
                hints.append(
                    f"known objects for {param.name}: {', '.join(fitting[:8])}{', ...' if len(fitting) > 8 else ''}"
                )
        elif not cd.is_subtype(kind, ca.param_types[i]):
            wanted = " or ".join(ca.param_types[i])
            detail = f"argument {i + 1} ({param.name}) must be a {wanted}, but {arg} is a {kind}"
            reasons.append(Reason(ReasonKind.TYPE_MISMATCH, detail, bindings=((param.name, arg),)))
            fitting = [o for o, t in objects.items() if cd.is_subtype(t, ca.param_types[i])]
            if fitting:
                fitting.sort(key=lambda o: -difflib.SequenceMatcher(None, arg, o).ratio())
                hints.append(f"objects of type {wanted}: {', '.join(fitting[:5])}")
    return _fail(step, reasons, hints) if reasons else None


def _normalized(cd: CompiledDomain, state: State, step: Step) -> Step:
    """The step with names lower-cased where that makes them known (PDDL is case-insensitive)."""
    action = step.action if step.action in cd.actions else step.action.lower()
    args = tuple(a if a in state.objects else a.lower() for a in step.args)
    return Step(action, args, step.add, step.delete)


def _precondition_failure(
    cd: CompiledDomain, ca: CompiledAction, state: State, step: Step, view: tuple
) -> Diagnosis:
    memo = state_memo(cd, state)
    explainer = None
    args = step.args
    failures: list[Failure] = []
    reasons: list[Reason] = []
    for (conj, fn), used in zip(ca.conjuncts, ca.conjunct_params, strict=True):
        if fn(*view, *args):
            continue
        # The explanation of a ground conjunct depends only on the state: share it between steps.
        key = ("why", id(conj), tuple(args[i] for i in used))
        hit = memo.get(key)
        if hit is None:
            if explainer is None:
                explainer = Explainer(cd, state)
            env = {p.name: a for p, a in zip(ca.action.params, args, strict=True)}
            found = tuple(explainer.explain(conj, env))
            hit = memo[key] = (
                found,
                tuple(
                    Reason(
                        ReasonKind.UNSATISFIED_PRECONDITION, f.sentence("precondition"), f.literal, f.bindings
                    )
                    for f in found
                ),
            )
        failures.extend(hit[0])
        reasons.extend(hit[1])
    return _fail(step, reasons, repair_hints(cd, state, failures, exclude=step))


def _effect_mismatch(step: Step, facts: frozenset[Fact], adds: list[Fact], dels: list[Fact]) -> list[Reason]:
    """Claimed vs true effects: a no-op change may be omitted, anything not an effect may not be claimed."""
    add_set = frozenset(adds)
    del_set = frozenset(dels) - add_set
    reasons = []
    if step.add is not None:
        claimed = {atom_fact(a) for a in step.add}
        for fact in sorted((add_set - facts) - claimed):
            reasons.append(
                Reason(ReasonKind.EFFECT_MISMATCH, f"missing add effect {fact_text(fact)}", fact_text(fact))
            )
        for fact in sorted(claimed - add_set):
            detail = f"claimed add effect {fact_text(fact)} is not an effect of the action"
            reasons.append(Reason(ReasonKind.EFFECT_MISMATCH, detail, fact_text(fact)))
    if step.delete is not None:
        claimed = {atom_fact(a) for a in step.delete}
        for fact in sorted((del_set & facts) - claimed):
            text = f"(not {fact_text(fact)})"
            reasons.append(Reason(ReasonKind.EFFECT_MISMATCH, f"missing delete effect {text}", text))
        for fact in sorted(claimed - del_set):
            text = f"(not {fact_text(fact)})"
            reasons.append(
                Reason(ReasonKind.EFFECT_MISMATCH, f"claimed delete effect {text} is not an effect", text)
            )
    return reasons


def check_step(
    domain: Domain, state: State, step: Step, numeric: Mapping[Atom, float] | None = None
) -> Diagnosis:
    """Validate one step in ``state``: ok with the transition, or the reasons with a message and hints."""
    cd = compile_domain(domain)
    ca = cd.actions.get(step.action)
    if ca is None or len(step.args) != ca.arity or not _args_fit(cd, ca, state, step.args):
        normal = _normalized(cd, state, step)
        if normal != step and _check_signature(cd, state, normal) is None:
            return check_step(domain, state, normal, numeric)
        return _check_signature(cd, state, step) or _fail(
            step, [Reason(ReasonKind.UNKNOWN_OBJECT, "malformed step")], []
        )
    view = cd.view(state)
    if not ca.pre(*view, *step.args):
        return _precondition_failure(cd, ca, state, step, view)
    num = {atom_fact(k): float(v) for k, v in numeric.items()} if numeric else _NO_NUMERIC
    adds, dels, cost = ca.eff(*view, num, *step.args)
    facts = view[0]
    if not cd.has_costs:
        cost = 1.0
    if step.add is not None or step.delete is not None:
        reasons = _effect_mismatch(step, facts, adds, dels)
        if reasons:
            truth = " ".join(
                [fact_text(f) for f in sorted(set(adds) - facts)]
                + [f"(not {fact_text(f)})" for f in sorted((set(dels) - set(adds)) & facts)]
            )
            hint = f"the true effects are: {truth}" if truth else "the step changes nothing"
            diagnosis = _fail(step, reasons, [hint])
            return Diagnosis(
                False,
                step,
                diagnosis.reasons,
                diagnosis.message,
                diagnosis.hints,
                cost,
                (state, tuple(adds), tuple(dels)),
            )
    return Diagnosis(True, step, (), f"{step}: ok", (), cost, (state, tuple(adds), tuple(dels)))


def _args_fit(cd: CompiledDomain, ca: CompiledAction, state: State, args: tuple[str, ...]) -> bool:
    """Fast check that every argument is a known object of the parameter's type."""
    sets = cd.view(state)[2]
    return all(a in sets[s] for a, s in zip(args, ca.param_slots, strict=True))
