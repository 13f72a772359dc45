"""Closed-world PDDL semantics: formula evaluation and action application over a State.

Every action schema is compiled once per Domain into plain Python (generated source, ``exec``):
the precondition becomes ``pre(T, O, a0, a1, ...) -> bool`` and the effect becomes
``eff(T, O, N, a0, ...) -> (adds, deletes, cost)``, where ``T`` is the state's atoms as a set of
tuples ``("on", "x", "y")`` (cheap to hash), ``O`` a list of per-type object tuples (quantifier
domains) and ``N`` the numeric fluents used by action costs. The step checker's fast path only
calls these functions, which is what makes ~10 µs per step check possible.
"""

from __future__ import annotations

import itertools
from collections import OrderedDict
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from gsr.errors import GSRError
from gsr.pddl.model import (
    Action,
    And,
    AndEffect,
    Atom,
    Domain,
    Effect,
    Equals,
    Exists,
    Forall,
    ForallEffect,
    Formula,
    ForN,
    ForPairs,
    Imply,
    Increase,
    Literal,
    Not,
    Or,
    TypedVar,
    When,
    is_variable,
)
from gsr.pddl.walk import conjuncts, effect_leaves, effect_literals, free_variables, negate
from gsr.state import State

Fact = tuple[str, ...]
Bindings = Mapping[str, str]

_COMPILED_LIMIT = 64  # compiled domains kept alive (keyed by id; the Domain itself is held too)
_COMPILED: OrderedDict[int, CompiledDomain] = OrderedDict()
_LAST: CompiledDomain | None = None


def has_perfect_pairing(lefts: list[Any], rights: list[Any], ok: Callable[[Any, Any], bool]) -> bool:
    """True when every left object pairs with a distinct right object (bipartite matching)."""
    adjacency = {a: [b for b in rights if ok(a, b)] for a in lefts}
    match: dict[Any, Any] = {}

    def augment(a: Any, seen: set[Any]) -> bool:
        for b in adjacency[a]:
            if b in seen:
                continue
            seen.add(b)
            if b not in match or augment(match[b], seen):
                match[b] = a
                return True
        return False

    return all(augment(a, set()) for a in lefts)


# ------------------------------------------------------------ code generation


class _Codegen:
    """Turns formulas and effects into Python source over ``T`` (fact set) and ``O`` (type lists)."""

    def __init__(self, compiled: CompiledDomain, where: str) -> None:
        self.compiled = compiled
        self.where = where
        self.counter = itertools.count()

    def fresh(self) -> str:
        return f"v{next(self.counter)}"

    def term(self, term: str, env: Mapping[str, str]) -> str:
        if is_variable(term):
            if term not in env:
                raise GSRError(f"{self.where}: free variable {term}")
            return env[term]
        return repr(term)

    def fact(self, atom: Atom, env: Mapping[str, str]) -> str:
        parts = [repr(atom.predicate), *(self.term(a, env) for a in atom.args)]
        return f"({', '.join(parts)},)"

    def binders(self, params: tuple[TypedVar, ...], env: dict[str, str]) -> str:
        loops = []
        for p in params:
            name = self.fresh()
            env[p.name] = name
            loops.append(f"for {name} in O[{self.compiled.type_slot(p.types)}]")
        return " ".join(loops)

    def tuples(self, params: tuple[TypedVar, ...]) -> str:
        """Source for the list of all typed bindings of ``params`` as tuples."""
        lists = ", ".join(f"O[{self.compiled.type_slot(p.types)}]" for p in params)
        return f"list(_product({lists}))"

    def join(
        self, params: tuple[TypedVar, ...], conjuncts: list[Formula], env: Mapping[str, str]
    ) -> tuple[list[str], list[str], dict[str, str]]:
        """(guards, clauses, env): ``for``/``if`` clauses enumerating the bindings of ``params`` that satisfy ``conjuncts``.

        Positive atoms over the quantified variables are joined through the state's fact index
        ``K`` (``K[(pred, position, value)]`` / ``K[(pred,)]``) instead of looping over every
        object: ``(exists (?z) (on ?z ?o))`` reads only the facts ``(on * o)``. Guards are the
        conjuncts that mention no quantified variable, plus a cheap emptiness test of the first
        index entry, to be checked before the loops start.
        """
        inner = dict(env)
        unbound = {p.name: p for p in params}
        names = set(unbound)
        guards = [self.expr(c, env) for c in conjuncts if not (free_variables(c) & names)]
        remaining = [c for c in conjuncts if free_variables(c) & names]
        clauses: list[str] = []
        while unbound:
            best, best_score = None, -1
            for c in remaining:
                if isinstance(c, Atom) and any(a in unbound for a in c.args):
                    score = sum(1 for a in c.args if a not in unbound)
                    if score > best_score:
                        best, best_score = c, score
            if best is None:
                break
            remaining.remove(best)
            fname = self.fresh()
            bound = [(j, self.term(a, inner)) for j, a in enumerate(best.args, 1) if a not in unbound]
            key = f"({best.predicate!r}, {bound[0][0]}, {bound[0][1]})" if bound else f"({best.predicate!r},)"
            if not clauses:
                guards.append(f"K.get({key})")
            clauses.append(f"for {fname} in K.get({key}, ())")
            clauses.extend(f"if {fname}[{j}] == {e}" for j, e in bound[1:])
            for j, a in enumerate(best.args, 1):
                if a in unbound:
                    var = self.fresh()
                    inner[a] = var
                    slot = self.compiled.type_slot(unbound.pop(a).types)
                    clauses.append(f"for {var} in ({fname}[{j}],)")
                    clauses.append(f"if {var} in S[{slot}]")
                elif all(j != b for b, _ in bound):  # a variable repeated within this atom
                    clauses.append(f"if {fname}[{j}] == {inner[a]}")
        for name, p in unbound.items():
            var = self.fresh()
            inner[name] = var
            clauses.append(f"for {var} in O[{self.compiled.type_slot(p.types)}]")
        if remaining:
            clauses.append(f"if {self.expr(And(tuple(remaining)), inner)}")
        return guards, clauses, inner

    def expr(self, f: Formula, env: Mapping[str, str]) -> str:
        if isinstance(f, Atom):
            return f"({self.fact(f, env)} in T)"
        if isinstance(f, Equals):
            return f"({self.term(f.left, env)} == {self.term(f.right, env)})"
        if isinstance(f, Not):
            return f"(not {self.expr(f.formula, env)})"
        if isinstance(f, And):
            return "(" + " and ".join(self.expr(p, env) for p in f.parts) + ")" if f.parts else "True"
        if isinstance(f, Or):
            return "(" + " or ".join(self.expr(p, env) for p in f.parts) + ")" if f.parts else "False"
        if isinstance(f, Imply):
            return f"((not {self.expr(f.condition, env)}) or {self.expr(f.then, env)})"
        if isinstance(f, Exists):
            conj = list(conjuncts(f.body))
            if _has_generator(f.params, conj):
                guards, clauses, _ = self.join(f.params, conj, env)
                return f"({' and '.join(guards)} and any(True {' '.join(clauses)}))"
        if isinstance(f, Forall):
            conj = list(conjuncts(negate(f.body)))
            if _has_generator(f.params, conj):  # forall x: b  ==  not exists x: not b
                guards, clauses, _ = self.join(f.params, conj, env)
                return f"(not ({' and '.join(guards)} and any(True {' '.join(clauses)})))"
        if isinstance(f, (Exists, Forall)):
            inner = dict(env)
            loops = self.binders(f.params, inner)
            fn = "any" if isinstance(f, Exists) else "all"
            return f"{fn}({self.expr(f.body, inner)} {loops})"
        if isinstance(f, ForN):
            inner = dict(env)
            loops = self.binders(f.params, inner)
            return f"(sum(1 {loops} if {self.expr(f.body, inner)}) >= {int(f.count)})"
        if isinstance(f, ForPairs):
            inner = dict(env)
            a, b = self.fresh(), self.fresh()
            inner.update({p.name: f"{a}[{i}]" for i, p in enumerate(f.first)})
            inner.update({p.name: f"{b}[{i}]" for i, p in enumerate(f.second)})
            body = self.expr(f.body, inner)
            return f"_pairing({self.tuples(f.first)}, {self.tuples(f.second)}, lambda {a}, {b}: {body})"
        raise GSRError(f"{self.where}: cannot evaluate {type(f).__name__}")

    def effect(self, e: Effect, env: Mapping[str, str], indent: str, out: list[str]) -> None:
        if isinstance(e, Literal):
            target = "D" if e.negated else "A"
            out.append(f"{indent}{target}.append({self.fact(e.atom, env)})")
        elif isinstance(e, AndEffect):
            for part in e.parts:
                self.effect(part, env, indent, out)
        elif isinstance(e, When):
            out.append(f"{indent}if {self.expr(e.condition, env)}:")
            self.effect(e.effect, env, indent + "    ", out)
            out.append(f"{indent}    pass")
        elif isinstance(e, ForallEffect) and isinstance(e.effect, AndEffect):
            for part in e.effect.parts:  # forall distributes over and: each part gets its own join
                self.effect(ForallEffect(e.params, part), env, indent, out)
        elif isinstance(e, ForallEffect):
            if isinstance(e.effect, When) and _has_generator(e.params, list(conjuncts(e.effect.condition))):
                guards, clauses, inner = self.join(e.params, list(conjuncts(e.effect.condition)), env)
                clauses.insert(0, f"if {' and '.join(guards)}")
                body = e.effect.effect
            else:
                clauses, inner, body = [], dict(env), e.effect
                for p in e.params:
                    name = self.fresh()
                    inner[p.name] = name
                    clauses.append(f"for {name} in O[{self.compiled.type_slot(p.types)}]")
            for clause in clauses:
                out.append(f"{indent}{clause}:")
                indent += "    "
            self.effect(body, inner, indent, out)
            out.append(f"{indent}pass")
        elif isinstance(e, Increase):
            out.append(f"{indent}C += {self.amount(e.amount, env)}")
        else:
            raise GSRError(f"{self.where}: cannot apply effect {type(e).__name__}")

    def amount(self, amount: float | str, env: Mapping[str, str]) -> str:
        if isinstance(amount, (int, float)):
            return repr(float(amount))
        text = str(amount).strip()
        try:
            return repr(float(text))
        except ValueError:
            pass
        # A function term such as "(road-length ?a ?b)": its value comes from the numeric fluents N.
        tokens = text.strip("()").split()
        if not tokens:
            raise GSRError(f"{self.where}: empty cost expression")
        key = [repr(tokens[0].lower()), *(self.term(t.lower(), env) for t in tokens[1:])]
        return f"N.get(({', '.join(key)},), 0.0)"


def _has_generator(params: tuple[TypedVar, ...], conj: list[Formula]) -> bool:
    """True when a positive atom over a quantified variable can drive the enumeration."""
    names = {p.name for p in params}
    return any(isinstance(c, Atom) and any(a in names for a in c.args) for c in conj)


def _build(source: str, name: str) -> Callable[..., Any]:
    """Exec generated source and return the function called ``name``."""
    namespace: dict[str, Any] = {"_pairing": has_perfect_pairing, "_product": itertools.product}
    exec(compile(source, f"<gsr:{name}>", "exec"), namespace)
    return namespace[name]


# ------------------------------------------------------------ compiled domain


@dataclass(slots=True)
class CompiledAction:
    """An action schema compiled to Python functions."""

    action: Action
    arity: int
    param_types: tuple[tuple[str, ...], ...]
    param_slots: tuple[int, ...]
    pre: Callable[..., bool]
    eff: Callable[..., tuple[list[Fact], list[Fact], float]]
    conjuncts: tuple[tuple[Formula, Callable[..., bool]], ...]
    conjunct_params: tuple[tuple[int, ...], ...] = ()  # parameter positions each conjunct mentions


@dataclass(slots=True)
class CompiledDomain:
    """Per-domain compiled actions, quantifier type slots and a subtype memo."""

    domain: Domain
    slots: dict[tuple[str, ...], int] = field(default_factory=dict)
    actions: dict[str, CompiledAction] = field(default_factory=dict)
    has_costs: bool = False
    fluents: frozenset[str] = frozenset()  # predicates some effect changes (the others are static)
    _subtype: dict[tuple[str, tuple[str, ...]], bool] = field(default_factory=dict)
    _formulas: dict[tuple[int, tuple[str, ...]], tuple[Formula, Callable[..., bool]]] = field(
        default_factory=dict
    )

    def type_slot(self, types: tuple[str, ...]) -> int:
        """Index of the per-state object list for an (either-)type."""
        key = tuple(types)
        if key not in self.slots:
            self.slots[key] = len(self.slots)
        return self.slots[key]

    def is_subtype(self, type_name: str, of: tuple[str, ...]) -> bool:
        """Memoized Domain.is_subtype."""
        key = (type_name, of)
        hit = self._subtype.get(key)
        if hit is None:
            hit = self._subtype[key] = self.domain.is_subtype(type_name, of)
        return hit

    def formula_fn(self, formula: Formula, variables: tuple[str, ...] = ()) -> Callable[..., bool]:
        """``fn(T, O, S, K, *values)`` deciding ``formula`` with ``variables`` bound positionally (cached)."""
        key = (id(formula), variables)
        hit = self._formulas.get(key)
        if hit is not None and hit[0] is formula:
            return hit[1]
        gen = _Codegen(self, "formula")
        env = {v: f"b{i}" for i, v in enumerate(variables)}
        args = "".join(f", b{i}" for i in range(len(variables)))
        fn = _build(f"def f(T, O, S, K{args}):\n    return bool({gen.expr(formula, env)})\n", "f")
        self._formulas[key] = (formula, fn)  # holding the formula keeps id() unique
        return fn

    def _object_cache(self, state: State) -> tuple[CompiledDomain, list, list]:
        cached = state.__dict__.get("_gsr_objects")
        if cached is not None and cached[0] is self and len(cached[1]) == len(self.slots):
            return cached
        objs = state.objects
        lists = [tuple(o for o, t in objs.items() if self.is_subtype(t, types)) for types in self.slots]
        cached = (self, lists, [frozenset(x) for x in lists])
        # State is a frozen dataclass: write the cache into its __dict__ directly.
        state.__dict__["_gsr_objects"] = cached
        return cached

    def object_lists(self, state: State) -> list[tuple[str, ...]]:
        """The state's objects grouped per type slot, in declaration order (cached on the state)."""
        return self._object_cache(state)[1]

    def object_sets(self, state: State) -> list[frozenset[str]]:
        """Like object_lists, as sets for membership tests."""
        return self._object_cache(state)[2]

    def view(self, state: State) -> tuple[frozenset[Fact], list, list, dict]:
        """``(T, O, S, K)``: what compiled functions read (facts, object lists/sets per slot, fact index)."""
        d = state.__dict__
        cached = d.get("_gsr_view")
        if cached is not None and cached[0] is self and len(cached[2]) == len(self.slots):
            return cached[1]
        _, lists, sets = self._object_cache(state)
        view = (facts_of(state), lists, sets, fact_index(state))
        d["_gsr_view"] = (self, view, lists)
        return view


def _effect_predicates(e: Effect) -> set[str]:
    return {lit.atom.predicate for lit in effect_literals(e)}


def _effect_has_cost(e: Effect) -> bool:
    return any(isinstance(leaf, Increase) for leaf in effect_leaves(e))


def _compile_action(cd: CompiledDomain, action: Action) -> CompiledAction:
    where = f"action {action.name}"
    names = [f"a{i}" for i in range(len(action.params))]
    env = {p.name: n for p, n in zip(action.params, names, strict=True)}
    args = "".join(f", {n}" for n in names)
    gen = _Codegen(cd, where)
    pre_src = f"def pre(T, O, S, K{args}):\n    return bool({gen.expr(action.precondition, env)})\n"
    lines = [f"def eff(T, O, S, K, N{args}):", "    A = []", "    D = []", "    C = 0.0"]
    gen.effect(action.effect, env, "    ", lines)
    lines.append("    return A, D, C")
    conj = []
    for c in conjuncts(action.precondition):
        src = f"def c(T, O, S, K{args}):\n    return bool({gen.expr(c, env)})\n"
        conj.append((c, _build(src, "c")))
    return CompiledAction(
        action=action,
        arity=len(action.params),
        param_types=tuple(tuple(p.types) for p in action.params),
        param_slots=tuple(cd.type_slot(tuple(p.types)) for p in action.params),
        pre=_build(pre_src, "pre"),
        eff=_build("\n".join(lines) + "\n", "eff"),
        conjuncts=tuple(conj),
        conjunct_params=tuple(
            tuple(i for i, p in enumerate(action.params) if p.name in free_variables(c)) for c, _ in conj
        ),
    )


def compile_domain(domain: Domain) -> CompiledDomain:
    """The compiled form of ``domain`` (built once, then cached by identity)."""
    global _LAST
    last = _LAST
    if last is not None and last.domain is domain and len(last.actions) == len(domain.actions):
        return last  # the common case: one domain checked over and over
    hit = _COMPILED.get(id(domain))
    if hit is not None and hit.domain is domain and len(hit.actions) == len(domain.actions):
        _COMPILED.move_to_end(id(domain))
        _LAST = hit
        return hit
    cd = CompiledDomain(domain)
    for name, action in domain.actions.items():
        cd.actions[name] = _compile_action(cd, action)
    cd.has_costs = any(_effect_has_cost(a.effect) for a in domain.actions.values())
    cd.fluents = frozenset(p for a in domain.actions.values() for p in _effect_predicates(a.effect))
    _COMPILED[id(domain)] = cd
    _LAST = cd
    if len(_COMPILED) > _COMPILED_LIMIT:
        _COMPILED.popitem(last=False)
    return cd


# ------------------------------------------------------------ state views


def facts_of(state: State) -> frozenset[Fact]:
    """The state's atoms as tuples ``(predicate, *args)`` (cached on the state)."""
    cached = state.__dict__.get("_gsr_facts")
    if cached is None:
        cached = frozenset((a.predicate, *a.args) for a in state.atoms)
        state.__dict__["_gsr_facts"] = cached
    return cached


def _index_keys(f: Fact) -> list[tuple]:
    return [f[:1], *((f[0], j, f[j]) for j in range(1, len(f)))]


def _index(facts: Iterable[Fact]) -> dict[tuple, tuple[Fact, ...]]:
    index: dict[tuple, list[Fact]] = {}
    for f in sorted(facts):  # sorted: witnesses and hints must not depend on hash order
        for key in _index_keys(f):
            index.setdefault(key, []).append(f)
    return {k: tuple(v) for k, v in index.items()}


def fact_index(state: State) -> dict[tuple, tuple[Fact, ...]]:
    """``K``: facts by ``(pred,)`` and by ``(pred, position, value)`` (cached on the state)."""
    cached = state.__dict__.get("_gsr_index")
    if cached is None:
        cached = _index(facts_of(state))
        state.__dict__["_gsr_index"] = cached
    return cached


def fact_atom(fact: Fact) -> Atom:
    """The Atom for a fact tuple."""
    return Atom(fact[0], tuple(fact[1:]))


def atom_fact(atom: Atom) -> Fact:
    """The fact tuple for an Atom."""
    return (atom.predicate, *atom.args)


def successor(state: State, adds: Iterable[Fact], deletes: Iterable[Fact]) -> State:
    """The state after deleting then adding facts; caches carry over (same objects)."""
    adds = frozenset(adds)
    deletes = frozenset(deletes) - adds  # an atom both added and deleted ends true
    facts = (facts_of(state) - deletes) | adds
    atoms = (state.atoms - {fact_atom(f) for f in deletes}) | {fact_atom(f) for f in adds}
    new = State(atoms, state.objects)
    new.__dict__["_gsr_facts"] = facts
    if "_gsr_objects" in state.__dict__:
        new.__dict__["_gsr_objects"] = state.__dict__["_gsr_objects"]
    old = state.__dict__.get("_gsr_index")
    if old is not None:  # update only the index entries the change touches
        before = facts_of(state)
        index = dict(old)
        for f in sorted(deletes & before):
            for key in _index_keys(f):
                index[key] = tuple(g for g in index[key] if g != f)
        for f in sorted(adds - before):
            for key in _index_keys(f):
                index[key] = (*index.get(key, ()), f)
        new.__dict__["_gsr_index"] = index
    return new


# ------------------------------------------------------------ public API


def _numeric(numeric: Mapping[Atom, float] | None) -> dict[Fact, float]:
    return {atom_fact(k): float(v) for k, v in (numeric or {}).items()}


def holds(domain: Domain, formula: Formula, state: State, bindings: Bindings | None = None) -> bool:
    """True when ``formula`` holds in ``state`` (closed world) under ``bindings`` (variable -> object)."""
    cd = compile_domain(domain)
    variables = tuple(sorted(bindings)) if bindings else ()
    fn = cd.formula_fn(formula, variables)
    values = [bindings[v] for v in variables] if bindings else []
    return fn(*cd.view(state), *values)


def goal_holds(domain: Domain, goal: Formula | Any, state: State) -> bool:
    """True when the goal (a Formula or a gsr.step.Goal) holds in ``state``."""
    formula = getattr(goal, "formula", goal)
    return holds(domain, formula, state)


def _compiled_action(domain: Domain, action_name: str, args: tuple[str, ...]) -> CompiledAction:
    ca = compile_domain(domain).actions.get(action_name)
    if ca is None:
        raise GSRError(f"unknown action {action_name!r}")
    if len(args) != ca.arity:
        raise GSRError(f"action {action_name} takes {ca.arity} arguments, got {len(args)}")
    return ca


def ground_effects(
    domain: Domain,
    action: Action | str,
    args: tuple[str, ...],
    state: State,
    numeric: Mapping[Atom, float] | None = None,
) -> tuple[frozenset[Atom], frozenset[Atom]]:
    """The (add, delete) atoms of ``action(args)`` in ``state``; deletes exclude atoms also added."""
    adds, deletes, _ = ground_effect_facts(domain, action, args, state, numeric)
    return frozenset(map(fact_atom, adds)), frozenset(map(fact_atom, deletes))


def ground_effect_facts(
    domain: Domain,
    action: Action | str,
    args: tuple[str, ...],
    state: State,
    numeric: Mapping[Atom, float] | None = None,
) -> tuple[frozenset[Fact], frozenset[Fact], float]:
    """(add facts, delete facts, cost) of ``action(args)``; ``when`` conditions use ``state``."""
    name = action if isinstance(action, str) else action.name
    ca = _compiled_action(domain, name, tuple(args))
    cd = compile_domain(domain)
    adds, dels, cost = ca.eff(*cd.view(state), _numeric(numeric), *args)
    add_set = frozenset(adds)
    return add_set, frozenset(dels) - add_set, cost if cd.has_costs else 1.0


def action_cost(domain: Domain, action_name: str, args: tuple[str, ...], state: State, numeric=None) -> float:
    """The step's cost: the ``total-cost`` increase with :action-costs, else 1 (unit cost)."""
    return ground_effect_facts(domain, action_name, args, state, numeric)[2]


def applicable(domain: Domain, state: State, action_name: str, args: tuple[str, ...]) -> bool:
    """True when the action exists, the arity fits and the precondition holds (types not checked)."""
    cd = compile_domain(domain)
    ca = cd.actions.get(action_name)
    if ca is None or len(args) != ca.arity:
        return False
    return ca.pre(*cd.view(state), *args)


def apply(domain: Domain, state: State, action_name: str, args: tuple[str, ...]) -> State:
    """The state after ``action_name(args)``; raises GSRError when it is not applicable."""
    if not applicable(domain, state, action_name, tuple(args)):
        raise GSRError(f"({' '.join((action_name, *args))}) is not applicable")
    adds, dels, _ = ground_effect_facts(domain, action_name, tuple(args), state)
    return successor(state, adds, dels)
