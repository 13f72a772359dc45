"""PDDL writer: readable, indented text that parses back to an equal model and that Fast Downward reads."""

from __future__ import annotations

from collections.abc import Iterable

from gsr.pddl.model import (
    OBJECT,
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
    Predicate,
    Problem,
    TypedVar,
    When,
)

_WIDTH = 96  # a formula longer than this on one line is broken over several
_STEP = "  "


def _number(value: float) -> str:
    """``1`` rather than ``1.0``: Fast Downward wants integer action costs."""
    return str(int(value)) if float(value).is_integer() else repr(float(value))


def _type(types: tuple[str, ...]) -> str:
    return types[0] if len(types) == 1 else f"(either {' '.join(types)})"


def _typed_vars(params: Iterable[TypedVar]) -> str:
    """``?x - block ?y``: object-typed parameters are written bare only after the last typed one
    (a bare name before ``- t`` would take type t)."""
    params = list(params)
    typed = [i for i, p in enumerate(params) if p.types != (OBJECT,)]
    last = typed[-1] if typed else -1
    return " ".join(p.name if i > last else f"{p.name} - {_type(p.types)}" for i, p in enumerate(params))


def _typed_names(names: dict[str, str]) -> list[str]:
    """Objects grouped by type, one group per line: ``a b c - block``."""
    groups: dict[str, list[str]] = {}
    for name, type_name in names.items():
        groups.setdefault(type_name, []).append(name)
    # Untyped names go last: on one line, names before "- t" would take that type.
    ordered = sorted(groups.items(), key=lambda item: item[0] == OBJECT)
    return [" ".join(group) + ("" if t == OBJECT else f" - {t}") for t, group in ordered]


def _atom(atom: Atom) -> str:
    return f"({' '.join((atom.predicate, *atom.args))})"


def _children(f: Formula) -> tuple[str, list[Formula]] | None:
    """Head text and sub-formulas of a compound formula (None for atoms and equalities)."""
    match f:
        case Not(formula=g):
            return "not", [g]
        case And(parts=parts):
            return "and", list(parts)
        case Or(parts=parts):
            return "or", list(parts)
        case Imply(condition=c, then=t):
            return "imply", [c, t]
        case Exists(params=params, body=body):
            return f"exists ({_typed_vars(params)})", [body]
        case Forall(params=params, body=body):
            return f"forall ({_typed_vars(params)})", [body]
        case ForN(count=n, params=params, body=body):
            return f"forn ({n}) ({_typed_vars(params)})", [body]
        case ForPairs(first=first, second=second, body=body):
            return f"forpairs ({_typed_vars(first)}) ({_typed_vars(second)})", [body]
    return None


def inline_formula(f: Formula) -> str:
    match f:
        case Atom():
            return _atom(f)
        case Equals(left=left, right=right):
            return f"(= {left} {right})"
    head, parts = _children(f) or ("", [])
    return "(" + " ".join([head, *(inline_formula(p) for p in parts)]) + ")"


def write_formula(f: Formula, indent: int = 0) -> str:
    """A formula as PDDL; long ones are broken over lines, continuation lines indented by ``indent``."""
    text = inline_formula(f)
    compound = _children(f)
    if compound is None or len(text) + indent <= _WIDTH or not compound[1]:
        return text
    head, parts = compound
    inner = indent + len(_STEP)
    lines = [f"({head}"] + [" " * inner + write_formula(p, inner) for p in parts]
    return "\n".join(lines) + ")"


def _effect_children(e: Effect) -> tuple[str, list[Effect]] | None:
    match e:
        case AndEffect(parts=parts):
            return "and", list(parts)
        case ForallEffect(params=params, effect=inner):
            return f"forall ({_typed_vars(params)})", [inner]
        case When(condition=condition, effect=inner):
            return f"when {inline_formula(condition)}", [inner]
    return None


def effect_inline(e: Effect) -> str:
    match e:
        case Literal(atom=atom, negated=negated):
            return f"(not {_atom(atom)})" if negated else _atom(atom)
        case Increase(function=function, args=args, amount=amount):
            value = amount if isinstance(amount, str) else _number(amount)
            return f"(increase ({' '.join((function, *args))}) {value})"
    head, parts = _effect_children(e) or ("", [])
    return "(" + " ".join([head, *(effect_inline(p) for p in parts)]) + ")"


def write_effect(e: Effect, indent: int = 0) -> str:
    """An effect as PDDL; long ones are broken over lines like :func:`write_formula`."""
    text = effect_inline(e)
    compound = _effect_children(e)
    if compound is None or len(text) + indent <= _WIDTH or not compound[1]:
        return text
    head, parts = compound
    if isinstance(e, When):  # keep a long condition readable too
        inner = indent + len(_STEP)
        condition = write_formula(e.condition, inner)
        return f"(when {condition}\n{' ' * inner}{write_effect(e.effect, inner)})"
    inner = indent + len(_STEP)
    lines = [f"({head}"] + [" " * inner + write_effect(p, inner) for p in parts]
    return "\n".join(lines) + ")"


def _declaration(p: Predicate) -> str:
    return f"({' '.join(filter(None, (p.name, _typed_vars(p.params))))})"


def _section(keyword: str, lines: list[str], indent: str = _STEP) -> list[str]:
    """``(:keyword`` with one item per line, or a single line when short."""
    if not lines:
        return [f"{indent}({keyword})"]
    one = f"{indent}({keyword} {' '.join(lines)})"
    if len(one) <= _WIDTH:
        return [one]
    inner = indent + _STEP
    return [f"{indent}({keyword}", *(inner + line for line in lines), f"{indent})"]


def _types(domain: Domain) -> list[str]:
    groups: dict[tuple[str, ...], list[str]] = {}
    for name, parents in domain.types.items():
        if name != OBJECT:  # several parents are written as (either ...), which parses back the same
            groups.setdefault(parents, []).append(name)
    ordered = sorted(groups.items(), key=lambda item: item[0] == (OBJECT,))  # untyped last, as above
    return [
        " ".join(names) + ("" if parents == (OBJECT,) else f" - {_type(parents)}")
        for parents, names in ordered
    ]


def _action(action: Action) -> list[str]:
    pad = _STEP * 2
    indent = len(pad) + len(":precondition ")
    return [
        f"{_STEP}(:action {action.name}",
        f"{pad}:parameters ({_typed_vars(action.params)})",
        f"{pad}:precondition {write_formula(action.precondition, indent)}",
        f"{pad}:effect {write_effect(action.effect, len(pad) + len(':effect '))})",
    ]


def write_domain(domain: Domain) -> str:
    """A Domain as a PDDL domain file."""
    lines = [f"(define (domain {domain.name})"]
    if domain.requirements:
        lines.append(f"{_STEP}(:requirements {' '.join(domain.requirements)})")
    if len(domain.types) > 1 or OBJECT not in domain.types:
        lines += _section(":types", _types(domain))
    if domain.constants:
        lines += _section(":constants", _typed_names(domain.constants))
    lines += _section(":predicates", [_declaration(p) for p in domain.predicates.values()])
    if domain.functions:
        lines += _section(":functions", [_declaration(f) + " - number" for f in domain.functions.values()])
    for axiom in domain.axioms:
        head = _declaration(Predicate(axiom.name, axiom.params))
        lines += ["", f"{_STEP}(:derived {head}", f"{_STEP * 2}{write_formula(axiom.body, len(_STEP) * 2)})"]
    for action in domain.actions.values():
        lines += ["", *_action(action)]
    return "\n".join(lines) + "\n)\n"


def write_problem(problem: Problem) -> str:
    """A Problem as a PDDL problem file (init atoms sorted, so the output is deterministic)."""
    lines = [f"(define (problem {problem.name})", f"{_STEP}(:domain {problem.domain_name})"]
    if problem.requirements:
        lines.append(f"{_STEP}(:requirements {' '.join(problem.requirements)})")
    lines += _section(":objects", _typed_names(problem.objects))
    init = [_atom(a) for a in sorted(problem.init, key=lambda a: (a.predicate, a.args))]
    init += [f"(= {_atom(f)} {_number(v)})" for f, v in problem.init_numeric.items()]
    lines += _section(":init", init)
    lines.append(f"{_STEP}(:goal {write_formula(problem.goal, len(_STEP) * 2)})")
    if problem.metric is not None:
        lines.append(f"{_STEP}(:metric {problem.metric[0]} ({problem.metric[1]}))")
    return "\n".join(lines) + "\n)\n"
