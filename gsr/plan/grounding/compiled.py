"""Compiled per-schema precondition grounding: one generated Python function per action schema.

``general_variant`` in gsr.plan.grounding.fixpoint interprets a schema's precondition conjuncts for every
binding (a kind dispatch per conjunct, Formula objects for every simplified part, their relaxed cores, and
at interning a DNF scan of each). Here each schema's conjunct list is compiled once per domain
into the source of a function (``compile``/``exec``) that, for one binding, builds the fluent
literals as ``(predicate, args)`` keys inline, tests static atoms and (in)equalities inline, and
takes every other conjunct from a memo over the values of its own variables, in *key form*: a
conjunction of key literals and *choices* (disjunctions whose alternatives are conjunctions of
key literals), with each choice's delete-relaxed test precomputed. The search task then needs no
per-binding Formula, relaxed core or DNF scan (gsr.plan.grounding.intern converts choices once per object).

What is compiled: atoms and negated atoms (fluent: keys; static: membership tests), equalities
and inequalities, and any other conjunct whose simplified ground form (by the grounding's
Simplifier, memoised per value of the conjunct's own variables) is a conjunction of literals and
of disjunctions of conjunctions of literals. What is not: a binding under which some conjunct
simplifies to anything deeper (a disjunction inside a conjunction inside a disjunction) is handed
to ``general_variant`` whole; the results are identical either way (tests compare both).
"""

from __future__ import annotations

from collections.abc import Callable

from gsr.errors import GSRError
from gsr.pddl.model import (
    FALSE,
    TRUE,
    And,
    Atom,
    Equals,
    Exists,
    Forall,
    Formula,
    Imply,
    Not,
    Or,
    TypedVar,
    is_variable,
)
from gsr.plan.grounding.effects import Variant
from gsr.plan.grounding.normalize import Schema
from gsr.plan.grounding.precondition import AtomKey
from gsr.plan.grounding.simplify import Simplifier

# A ground literal in key form, and a conjunction of them: (positive keys, negative keys).
KeyConj = tuple[tuple[AtomKey, ...], tuple[AtomKey, ...]]
# A choice: (its alternatives, what the delete relaxation tests of it: the positive keys of each
# alternative, or None when some alternative has none, i.e. the choice always holds relaxed).
Choice = tuple[tuple[KeyConj, ...], "tuple[tuple[AtomKey, ...], ...] | None"]
# A conjunct in key form: (positive keys, negative keys, choices, the relaxed tests of those
# choices that do not always hold). A memoised one is shared by every binding with the same values
# of its variables, so interning converts its keys once (gsr.plan.grounding.intern.precondition_dnf).
KeyCnf = tuple[
    tuple[AtomKey, ...], tuple[AtomKey, ...], tuple[Choice, ...], tuple[tuple[tuple[AtomKey, ...], ...], ...]
]

EMPTY: KeyCnf = ((), (), (), ())


class _General(Exception):
    """A simplified conjunct has a shape the key form does not hold (see module docstring)."""


GENERAL = object()  # memo value of such a conjunct: the binding goes to the general path
ALWAYS = object()  # key_alternatives of a true formula


def _literal(g: Formula) -> tuple[AtomKey, bool] | None:
    """(key, positive) of a ground literal, None for anything else."""
    kind = type(g)
    if kind is Atom:
        return (g.predicate, g.args), True  # type: ignore[union-attr]
    if kind is Not and type(g.formula) is Atom:  # type: ignore[union-attr]
        a = g.formula  # type: ignore[union-attr]
        return (a.predicate, a.args), False
    return None


def _conj(g: Formula) -> KeyConj:
    """A literal or conjunction of literals as a KeyConj; _General for anything else."""
    pos: list[AtomKey] = []
    neg: list[AtomKey] = []
    stack = [g]
    while stack:
        p = stack.pop()
        if type(p) is And:
            stack.extend(reversed(p.parts))  # type: ignore[union-attr]
            continue
        lit = _literal(p)
        if lit is None:
            raise _General
        (pos if lit[1] else neg).append(lit[0])
    return tuple(pos), tuple(neg)


def _choice(alts: list[KeyConj]) -> Choice:
    relax = None if any(not p for p, _ in alts) else tuple(p for p, _ in alts)
    return tuple(alts), relax


def key_alternatives(g: Formula) -> object:
    """A simplified ground formula as a list of KeyConj alternatives (nested disjunctions
    flattened; FALSE: none), ALWAYS for TRUE, GENERAL for a shape the key form does not hold."""
    if g is TRUE:
        return ALWAYS
    if g is FALSE:
        return []
    out: list[KeyConj] = []
    stack = [g]
    try:
        while stack:
            p = stack.pop()
            if type(p) is Or:
                stack.extend(reversed(p.parts))  # type: ignore[union-attr]
            else:
                out.append(_conj(p))
    except _General:
        return GENERAL
    return out


def key_cnf(g: Formula) -> object:
    """A simplified ground conjunct as a KeyCnf; None when it is FALSE, GENERAL when the key form
    cannot hold it."""
    if g is TRUE:
        return EMPTY
    if g is FALSE:
        return None
    pos: list[AtomKey] = []
    neg: list[AtomKey] = []
    choices: list[Choice] = []
    stack = [g]
    while stack:
        p = stack.pop()
        kind = type(p)
        if kind is And:
            stack.extend(reversed(p.parts))  # type: ignore[union-attr]
            continue
        if kind is Or:
            alts = key_alternatives(p)
            if alts is GENERAL:
                return GENERAL
            choices.append(_choice(alts))  # type: ignore[arg-type]
            continue
        lit = _literal(p)
        if lit is None:
            return GENERAL
        (pos if lit[1] else neg).append(lit[0])
    relax = tuple(r for _, r in choices if r is not None)
    return tuple(pos), tuple(neg), tuple(choices), relax


def _key_expr(atom: Atom, slots: dict[str, str]) -> str:
    """Source of an atom's (predicate, args) key with variables read from local slots."""
    args = [slots[a] if is_variable(a) else repr(a) for a in atom.args]
    inner = "(" + ", ".join(args) + ("," if len(args) == 1 else "") + ")"
    return f"({atom.predicate!r}, {inner})"


def _term(x: str, slots: dict[str, str]) -> str:
    return slots[x] if is_variable(x) else repr(x)


def compile_schema(
    schema: Schema,
    parts: list,
    kinds: tuple[int, ...],
    fluent_names: set[str],
    tables: dict[tuple, int] | None = None,
) -> Callable | None:
    """The factory of one schema's compiled precondition (see module docstring); None when a
    conjunct mentions a variable that is no parameter (the general path reports it per binding).

    ``parts`` are the schema's Parts (gsr.plan.grounding.fixpoint._parts: conjunct, memo key or OrSplit, kind)
    and ``kinds`` the kind codes (generic, skip, fluent, not fluent, distinct, split) in that order.
    The factory takes the per-problem (init keys, simplify, general, shared memo tables) and returns
    ``variant(binding) -> Variant | None``.

    ``tables`` numbers the memo tables by (kind, alpha-renamed conjunct), shared by all the schemas
    of one domain: the factory looks its tables up by that small number (a formula key would be
    hashed node by node, through Python ``__hash__``s, on every problem); ``factory.memos`` keeps
    the (kind, conjunct) keys. Without it, the tables are looked up by those keys.
    """
    try:
        return _compile(schema, parts, kinds, fluent_names, tables)
    except KeyError:  # an unknown variable in a conjunct's source
        return None


def _compile(
    schema: Schema,
    parts: list,
    kinds: tuple[int, ...],
    fluent_names: set[str],
    tables: dict[tuple, int] | None,
) -> Callable:
    generic, skip, fluent, not_fluent, distinct, _split = kinds
    names = [p.name for p in schema.all_params]
    slots = {n: f"v{k}" for k, n in enumerate(names)}
    head = [f"    {slots[n]} = b[{n!r}]" for n in names]
    body: list[str] = []
    memos: list[tuple[str, str, tuple]] = []  # (local name, table number's const, key)
    consts: dict[str, object] = {}
    objects: dict[tuple[str, ...], str] = {}  # object lists by type, read once per problem
    uses_extra = False

    # One-literal alternatives over the action's variables, built once per binding and shared by
    # the split disjunctions that repeat them (pick's ``(not (in ?o ?from))`` in three of them):
    # interning then converts one object (gsr.plan.grounding.intern._choice_ids caches by object).
    locals_: dict[str, str] = {}

    def local(source: str) -> str:
        name = locals_.get(source)
        if name is None:
            name = locals_[source] = f"a{len(locals_)}"
        return name

    def const(obj: object) -> str:
        name = f"C{len(consts)}"
        consts[name] = obj
        return name

    def memo_key(free: tuple[str, ...]) -> str:
        if len(free) == 1:
            return slots[free[0]]
        return "(" + ", ".join(slots[x] for x in free) + ("," if len(free) == 1 else "") + ")"

    def memo(what: str, part: Formula) -> tuple[str, str]:
        """A memo table shared by the alpha-equivalent conjuncts of every schema (pick's, open's and
        place_in's ``(not (exists (?z) (on ?z ?x)))``), and its key's source."""
        canon, order = canonical(part)
        name = f"M{len(memos)}"
        key = (what, canon)
        number = key if tables is None else tables.setdefault(key, len(tables))
        memos.append((name, const(number), key))
        return name, memo_key(order)

    for part, free, kind in parts:
        if kind == skip:
            continue
        if kind == fluent:
            body.append(f"    pos.append({_key_expr(part, slots)})")
            continue
        if kind == not_fluent:
            body.append(f"    neg.append({_key_expr(part.formula, slots)})")
            continue
        if kind == distinct:
            eq = part.formula
            body.append(f"    if {_term(eq.left, slots)} == {_term(eq.right, slots)}:\n        return None")
            continue
        if kind == generic and free is None:  # a conjunct over all the action's variables
            if type(part) is Atom and part.predicate != "=":  # a static atom outside the join
                body.append(f"    if {_key_expr(part, slots)} not in INIT:\n        return None")
                continue
            if type(part) is Not and type(part.formula) is Atom:  # a negated static atom
                body.append(f"    if {_key_expr(part.formula, slots)} in INIT:\n        return None")
                continue
            if type(part) is Equals:
                body.append(
                    f"    if {_term(part.left, slots)} != {_term(part.right, slots)}:\n        return None"
                )
                continue
            uses_extra = True
            alts = _fluent_alternatives(part, fluent_names, slots)
            if alts is not None:  # a disjunction of fluent literals (pick's on-or-in), inline
                body.append(_inline_choice(alts))
                continue
            if type(part) not in (Forall, Exists):
                body.append(f"    r = key_cnf(simplify({const(part)}, b))")
                body.append(_use_cnf("r"))
                continue
            # A quantifier over all the action's variables (open's "no open drawer above ?x"):
            # memoised like the narrower conjuncts below, in the table shared with the
            # alpha-equivalent conjuncts of other schemas (close's), one-literal fast path included.
        if kind == generic:  # memoised on the values of its own variables
            uses_extra = True
            m, key = memo("cnf", part)
            body.append(f"    r = {m}.get({key})")
            keys = _forall_literal(part, fluent_names, slots, objects)
            if keys is not None:  # one fluent literal per object: its keys directly
                sign, expr = keys
                value = f"({expr}, (), (), ())" if sign else f"((), {expr}, (), ())"
                body.append(
                    f"    if r is None:\n        q = {expr}\n        r = {m}[{key}] = {value.replace(expr, 'q')} if q else EMPTY"
                )
            else:
                body.append(
                    f"    if r is None:\n        r = {m}[{key}] = key_cnf_or_false(simplify({const(part)}, b))"
                )
            body.append(_use_cnf("r", false_marker=True))
            continue
        # kind == split: groups over fewer variables memoised, the disjuncts over all per binding
        uses_extra = True
        full, groups = free
        body.append("    alts = []")
        body.append("    while True:")  # one pass; `break` leaves it once the disjunction holds
        for group, _gnames in groups:
            m, key = memo("alternatives", group)
            body.append(f"        g = {m}.get({key})")
            keys = _forall_literal(group, fluent_names, slots, objects)
            if keys is not None:
                sign, expr = keys
                value = "[(q, ())]" if sign else "[((), q)]"
                body.append(
                    f"        if g is None:\n            q = {expr}\n            g = {m}[{key}] = {value} if q else ALWAYS"
                )
            else:
                body.append(
                    f"        if g is None:\n            g = {m}[{key}] = key_alternatives(simplify({const(group)}, b))"
                )
            body.append("        if g is ALWAYS:\n            break")
            body.append("        if g is GENERAL:\n            return general(b)")
            body.append("        alts += g")
        for q in full:
            if type(q) is Atom and q.predicate in fluent_names:
                body.append(f"        alts.append({local(f'(({_key_expr(q, slots)},), ())')})")
                continue
            if type(q) is Not and type(q.formula) is Atom and q.formula.predicate in fluent_names:
                body.append(f"        alts.append({local(f'((), ({_key_expr(q.formula, slots)},))')})")
                continue
            body.append(f"        g = key_alternatives(simplify({const(q)}, b))")
            body.append("        if g is ALWAYS:\n            break")
            body.append("        if g is GENERAL:\n            return general(b)")
            body.append("        alts += g")
        body.append("        if not alts:\n            return None")
        body.append(
            "        if len(alts) == 1:\n            pos += alts[0][0]\n            neg += alts[0][1]"
        )
        # A negative literal among the disjuncts over all variables: an alternative without
        # positive keys, so the delete relaxation always holds the choice (see _choice).
        holds = any(
            type(q) is Not and type(q.formula) is Atom and q.formula.predicate in fluent_names for q in full
        )
        make = "(tuple(alts), None)" if holds else "make_choice(alts)"
        body.append(f"        else:\n            choices.append({make})")
        body.append("        break")
    head += [f"    {name} = {source}" for source, name in locals_.items()]
    lines = ["def variant(b):", *head, "    pos = []", "    neg = []"]
    if uses_extra:
        lines.append("    choices = []")
        lines.append("    pieces = []")
    lines += body
    args = (
        "(" + ", ".join(slots[p.name] for p in schema.params) + ("," if len(schema.params) == 1 else "") + ")"
    )
    extra = "choices=tuple(choices), pieces=tuple(pieces)" if uses_extra else ""
    lines.append(f"    return Variant(NAME, {args}, b, SCHEMA, tuple(pos), tuple(neg), (), (), {extra})")
    source = "\n".join(lines)
    factory_src = (
        "def factory(INIT, simplify, general, SHARED):\n"
        + "".join(f"    {m} = SHARED.setdefault({c}, {{}})\n" for m, c, _ in memos)
        + "".join(f"    {name} = simplify.objects({types!r})\n" for types, name in objects.items())
        + "\n".join("    " + line for line in source.splitlines())
        + "\n    return variant\n"
    )
    env: dict[str, object] = {
        "Variant": Variant,
        "NAME": schema.name,
        "SCHEMA": schema,
        "key_cnf": key_cnf,
        "key_alternatives": key_alternatives,
        "key_cnf_or_false": key_cnf_or_false,
        "make_choice": _choice,
        "ALWAYS": ALWAYS,
        "GENERAL": GENERAL,
        "FALSE_CNF": FALSE_CNF,
        "EMPTY": EMPTY,
        **consts,
    }
    exec(compile(factory_src, f"<compiled precondition of {schema.name}>", "exec"), env)
    factory = env["factory"]
    factory.source = factory_src  # type: ignore[attr-defined]
    factory.memos = [key for _, _, key in memos]  # type: ignore[attr-defined]
    return factory  # type: ignore[return-value]


FALSE_CNF = object()  # memo value of a statically false conjunct (None means "not computed")


def key_cnf_or_false(g: Formula) -> object:
    """key_cnf with FALSE as FALSE_CNF (a memo needs None for "not computed")."""
    r = key_cnf(g)
    return FALSE_CNF if r is None else r


def _use_cnf(var: str, false_marker: bool = False) -> str:
    false = "FALSE_CNF" if false_marker else "None"
    return (
        f"    if {var} is {false}:\n        return None\n"
        f"    if {var} is GENERAL:\n        return general(b)\n"
        f"    if {var} is not EMPTY:\n"
        f"        if {var}[0]:\n            pos += {var}[0]\n"
        f"        pieces.append({var})"
    )


def _forall_literal(
    part: Formula, fluent_names: set[str], slots: dict[str, str], objects: dict[tuple[str, ...], str]
) -> tuple[bool, str] | None:
    """``(forall (?z) (not (on ?z ?o)))`` (NNF of ``(not (exists ...))``) or ``(forall (?z) (p ?z))``:
    (positive, source of the tuple of its literal keys, one per object of the variable's type);
    None for any other shape. The Simplifier gives the same literals (fluent ones never fold)."""
    if type(part) is not Forall or len(part.params) != 1:
        return None
    var = part.params[0]
    body, positive = part.body, True
    if type(body) is Not:
        body, positive = body.formula, False
    if type(body) is not Atom or body.predicate not in fluent_names:
        return None
    name = objects.setdefault(var.types, f"O{len(objects)}")
    args = [("q_" if a == var.name else slots[a] if is_variable(a) else repr(a)) for a in body.args]
    inner = "(" + ", ".join(args) + ("," if len(args) == 1 else "") + ")"
    return positive, f"tuple([({body.predicate!r}, {inner}) for q_ in {name}])"


def _fluent_alternatives(
    part: Formula, fluent_names: set[str], slots: dict[str, str]
) -> list[tuple[bool, str]] | None:
    """(positive, source of the literal's key) of each disjunct of a disjunction of fluent
    literals; None for any other formula."""
    if type(part) is not Or:
        return None
    out = []
    for q in part.parts:
        if type(q) is Atom and q.predicate in fluent_names:
            out.append((True, _key_expr(q, slots)))
        elif type(q) is Not and type(q.formula) is Atom and q.formula.predicate in fluent_names:
            out.append((False, _key_expr(q.formula, slots)))
        else:
            return None
    return out


def _inline_choice(alts: list[tuple[bool, str]]) -> str:
    """Source appending the Choice of a disjunction of fluent literals: ``_choice`` of its KeyConj
    alternatives with the relaxed test decided here (None as soon as one literal is negative)."""
    lines = []
    conjs = []
    for k, (positive, key) in enumerate(alts):
        lines.append(f"    p{k} = ({key},)")
        conjs.append(f"(p{k}, ())" if positive else f"((), p{k})")
    positive = all(sign for sign, _ in alts)
    relax = "(" + "".join(f"p{k}, " for k in range(len(alts))) + ")" if positive else "None"
    lines.append(f"    choices.append((({''.join(c + ', ' for c in conjs)}), {relax}))")
    return "\n".join(lines)


def bind(factory: Callable, simplify: Simplifier, general: Callable, shared: dict) -> Callable:
    """One problem's compiled precondition function (``shared``: the problem's memo tables, one
    dict for all the schemas)."""
    return factory(simplify.init_keys, simplify, general, shared)


def canonical(formula: Formula) -> tuple[Formula, tuple[str, ...]]:
    """An alpha-renamed copy of a formula (free variables ``?_f0``, ``?_f1``... in order of first
    occurrence, bound ones ``?_b1``...) and its free variables in that order: two conjuncts with
    the same copy simplify alike under the same values of those variables."""
    free: dict[str, str] = {}
    bound = [0]

    def term(x: str, scope: dict[str, str]) -> str:
        if not is_variable(x):
            return x
        if x in scope:
            return scope[x]
        if x not in free:
            free[x] = f"?_f{len(free)}"
        return free[x]

    def walk(f: Formula, scope: dict[str, str]) -> Formula:
        kind = type(f)
        if kind is Atom:
            return Atom(f.predicate, tuple(term(a, scope) for a in f.args))  # type: ignore[union-attr]
        if kind is Equals:
            return Equals(term(f.left, scope), term(f.right, scope))  # type: ignore[union-attr]
        if kind is Not:
            return Not(walk(f.formula, scope))  # type: ignore[union-attr]
        if kind is And or kind is Or:
            return kind(tuple(walk(p, scope) for p in f.parts))  # type: ignore[union-attr,call-arg]
        if kind is Imply:
            return Imply(walk(f.condition, scope), walk(f.then, scope))  # type: ignore[union-attr]
        if kind is Forall or kind is Exists:
            inner = dict(scope)
            params = []
            for p in f.params:  # type: ignore[union-attr]
                bound[0] += 1
                inner[p.name] = f"?_b{bound[0]}"
                params.append(TypedVar(inner[p.name], p.types))
            return kind(tuple(params), walk(f.body, inner))  # type: ignore[union-attr,call-arg]
        raise GSRError(f"unsupported formula in planner: {f!r}")

    copy = walk(formula, {})
    return copy, tuple(free)
