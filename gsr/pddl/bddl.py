"""BDDL reader (LIBERO and BEHAVIOR dialects) and expansion of the counting quantifiers forn / forpairs.

Both dialects share one grammar with PDDL (see grammar.lark). LIBERO adds ``:language``,
``:regions``, ``:fixtures`` and ``:obj_of_interest``; BEHAVIOR writes object names in goals
with a leading ``?`` (stored here without it) and uses forn / forpairs / fornpairs.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from lark import Token, Tree

from gsr.errors import GSRError, ParseError
from gsr.pddl.model import (
    FALSE,
    And,
    Atom,
    Domain,
    Equals,
    Exists,
    Forall,
    Formula,
    ForN,
    ForPairs,
    Imply,
    Not,
    Or,
    TypedVar,
)
from gsr.pddl.parser import Builder, parse_domain, read_text, requirements, syntax_tree

MAX_DISJUNCTS = 100_000
ROOM_PREDICATE = "inroom"  # BEHAVIOR: (inroom obj kitchen) names a room, not an object
_PI_EXPRESSION = re.compile(r"^([+-]?)(\d*\.?\d*)\*?pi(?:/(\d+\.?\d*))?$")

Value = float | str | tuple["Value", ...]


@dataclass
class Region:
    """A LIBERO region: ``(name (:target t) (:ranges ((x0 y0 x1 y1) ...)) (:yaw_rotation ((a b))) ...)``."""

    name: str
    target: str
    ranges: tuple[tuple[float, ...], ...] = ()
    yaw_rotation: tuple[tuple[float, ...], ...] = ()
    extra: dict[str, Value] = field(default_factory=dict)

    @property
    def qualified_name(self) -> str:
        """The name init/goal atoms use: ``<target>_<name>``."""
        return f"{self.target}_{self.name}"


@dataclass
class BddlProblem:
    """A parsed BDDL problem; ``init_false`` holds the negated init literals BEHAVIOR files may list."""

    name: str
    domain_name: str
    language: str | None
    regions: list[Region]
    fixtures: dict[str, str]
    objects: dict[str, str]
    obj_of_interest: list[str]
    init: list[Atom]
    goal: Formula
    init_false: list[Atom] = field(default_factory=list)
    scene_properties: dict[str, dict[str, Value]] = field(default_factory=dict)

    def all_objects(self) -> dict[str, str]:
        """Objects and fixtures together, name -> type."""
        return {**self.fixtures, **self.objects}


# ------------------------------------------------------------------ expansion


def _exact_type(object_type: str, wanted: str) -> bool:
    return object_type == wanted


def _bindings(
    params: tuple[TypedVar, ...], objects: Mapping[str, str], is_subtype: Callable[[str, str], bool]
) -> list[dict[str, str]]:
    """Every assignment of objects to ``params`` (in object order, so expansion is deterministic)."""
    domains = [[o for o, t in objects.items() if any(is_subtype(t, w) for w in p.types)] for p in params]
    return [dict(zip((p.name for p in params), combo, strict=True)) for combo in itertools.product(*domains)]


def substitute(formula: Formula, mapping: Mapping[str, str]) -> Formula:
    """Replace free variables by objects; variables re-bound by an inner quantifier are left alone."""
    match formula:
        case Atom(predicate=p, args=args):
            return Atom(p, tuple(mapping.get(a, a) for a in args))
        case Equals(left=left, right=right):
            return Equals(mapping.get(left, left), mapping.get(right, right))
        case Not(formula=f):
            return Not(substitute(f, mapping))
        case And(parts=parts):
            return And(tuple(substitute(p, mapping) for p in parts))
        case Or(parts=parts):
            return Or(tuple(substitute(p, mapping) for p in parts))
        case Imply(condition=c, then=t):
            return Imply(substitute(c, mapping), substitute(t, mapping))
    bound = {p.name for p in _params(formula)}
    inner = {k: v for k, v in mapping.items() if k not in bound}
    match formula:
        case Exists(params=params, body=body):
            return Exists(params, substitute(body, inner))
        case Forall(params=params, body=body):
            return Forall(params, substitute(body, inner))
        case ForN(count=n, params=params, body=body):
            return ForN(n, params, substitute(body, inner))
        case ForPairs(first=first, second=second, body=body):
            return ForPairs(first, second, substitute(body, inner))
    raise TypeError(f"not a formula: {formula!r}")


def _params(formula: Formula) -> tuple[TypedVar, ...]:
    if isinstance(formula, ForPairs):
        return formula.first + formula.second
    return formula.params  # type: ignore[union-attr]


class _Budget:
    """Counts generated disjuncts across one expansion, so nested quantifiers cannot explode."""

    def __init__(self) -> None:
        self.used = 0

    def take(self, count: int, what: str) -> None:
        self.used += count
        if count > MAX_DISJUNCTS or self.used > MAX_DISJUNCTS:
            raise GSRError(f"expanding {what} needs more than {MAX_DISJUNCTS:,} disjuncts")


def _pairings(first: list[dict[str, str]], second: list[dict[str, str]], body: Formula) -> Iterator[Formula]:
    """For each injective assignment, the conjunction of body instances."""
    for chosen in itertools.permutations(second, len(first)):
        yield And(tuple(substitute(body, {**a, **b}) for a, b in zip(first, chosen, strict=True)))


def _expand(
    formula: Formula, objects: Mapping[str, str], is_subtype: Callable[[str, str], bool], budget: _Budget
) -> Formula:
    match formula:
        case Atom() | Equals():
            return formula
        case Not(formula=f):
            return Not(_expand(f, objects, is_subtype, budget))
        case And(parts=parts):
            return And(tuple(_expand(p, objects, is_subtype, budget) for p in parts))
        case Or(parts=parts):
            return Or(tuple(_expand(p, objects, is_subtype, budget) for p in parts))
        case Imply(condition=c, then=t):
            return Imply(_expand(c, objects, is_subtype, budget), _expand(t, objects, is_subtype, budget))
        case Exists(params=params, body=body):
            return Exists(params, _expand(body, objects, is_subtype, budget))
        case Forall(params=params, body=body):
            return Forall(params, _expand(body, objects, is_subtype, budget))
        case ForN(count=n, params=params, body=body):
            inner = _expand(body, objects, is_subtype, budget)
            bindings = _bindings(params, objects, is_subtype)
            budget.take(math.comb(len(bindings), n), f"(forn ({n}) ...) over {len(bindings)} bindings")
            return Or(
                tuple(
                    And(tuple(substitute(inner, b) for b in subset))
                    for subset in itertools.combinations(bindings, n)
                )
            )
        case ForPairs(first=first, second=second, body=body):
            inner = _expand(body, objects, is_subtype, budget)
            left, right = _bindings(first, objects, is_subtype), _bindings(second, objects, is_subtype)
            budget.take(
                math.perm(len(right), len(left)), f"(forpairs ...) pairing {len(left)} with {len(right)}"
            )
            if len(left) > len(right):
                return FALSE
            return Or(tuple(_pairings(left, right, inner)))
    raise TypeError(f"not a formula: {formula!r}")


def expand_quantifiers(
    formula: Formula, objects: Mapping[str, str], is_subtype: Callable[[str, str], bool] | None = None
) -> Formula:
    """Rewrite ForN / ForPairs into Or/And over ``objects`` (name -> type); other nodes stay as they are.

    ``forn n``: a disjunction over the n-subsets of bindings; ``forpairs``: a disjunction over the
    injective assignments of second bindings to first ones. ``is_subtype(object_type, wanted)``
    decides which objects a typed variable ranges over (default: the exact type).
    Raises GSRError when the result would hold more than 100,000 disjuncts.
    """
    return _expand(formula, objects, is_subtype or _exact_type, _Budget())


def _fornpairs(
    count: int,
    first: tuple[TypedVar, ...],
    second: tuple[TypedVar, ...],
    body: Formula,
    objects: Mapping[str, str],
) -> Formula:
    """``fornpairs n``: some n first bindings paired one-to-one with n distinct second ones satisfy body."""
    left, right = _bindings(first, objects, _exact_type), _bindings(second, objects, _exact_type)
    size = math.comb(len(left), count) * math.perm(len(right), count)
    if size > MAX_DISJUNCTS:
        raise GSRError(f"expanding (fornpairs ({count}) ...) needs more than {MAX_DISJUNCTS:,} disjuncts")
    return Or(
        tuple(
            conjunct
            for subset in itertools.combinations(left, count)
            for conjunct in _pairings(list(subset), right, body)
        )
    )


# ----------------------------------------------------------------- parsing


class _BddlBuilder(Builder):
    """Formula builder for BDDL: ``?object`` terms, known names, counting quantifiers."""

    allow_counting = True

    def __init__(self, source: str, known: set[str], objects: dict[str, str]) -> None:
        super().__init__(source, is_object=known.__contains__)
        self.known = known
        self.objects = objects

    def term(self, token: Token, scope: frozenset[str], atom: Tree, index: int) -> str:
        name = str(token)
        if token.type == "VAR" and name not in scope:
            if name[1:] in self.known:
                return name[1:]
            raise self.error(f"{name} is neither a bound variable nor a declared object", token)
        if index == 1 and str(atom.children[0]) == ROOM_PREDICATE:
            return name
        return super().term(token, scope, atom, index)

    def counting(self, tree: Tree, scope: frozenset[str]) -> Formula:
        if tree.data != "fornpairs":
            return super().counting(tree, scope)
        # No model node for fornpairs: it is expanded here, over the problem's objects.
        count_token, first_tree, second_tree, body = tree.children
        first, second = self.typed_vars(first_tree), self.typed_vars(second_tree)
        inner = self.formula(body, scope | {p.name for p in first + second})
        try:
            return _fornpairs(self.count(count_token), first, second, inner, self.objects)
        except GSRError as err:
            raise self.error(str(err), tree) from None


def _value(node: Token | Tree) -> Value:
    """A region property value: a number, a pi expression such as -pi/2, a name, or a list."""
    if isinstance(node, Tree):
        return tuple(_value(c) for c in node.children)
    text = str(node)
    try:
        return float(text)
    except ValueError:
        pass
    match = _PI_EXPRESSION.match(text)
    if match:
        sign, factor, divisor = match.groups()
        value = (float(factor) if factor not in ("", ".") else 1.0) * math.pi / float(divisor or 1)
        return -value if sign == "-" else value
    return text


def _numbers(value: Value, builder: Builder, node: Tree) -> tuple[tuple[float, ...], ...]:
    """``((a b c d) ...)`` as tuples of floats."""
    rows = value if isinstance(value, tuple) else (value,)
    if not all(isinstance(r, tuple) and all(isinstance(x, float) for x in r) for r in rows):
        raise builder.error(f"expected a list of number lists, got {value!r}", node)
    return tuple(rows)  # type: ignore[arg-type]


def _properties(block: Tree, builder: Builder) -> tuple[Token, dict[str, tuple[Value, Tree]]]:
    head, *props = block.children
    found: dict[str, tuple[Value, Tree]] = {}
    for prop in props:
        key, *values = prop.children
        name = str(key)[1:]
        if name in found:
            raise builder.error(f"duplicate :{name} in {head}", key)
        parsed = tuple(_value(v) for v in values)
        found[name] = (parsed[0] if len(parsed) == 1 else parsed, prop)
    return head, found


def _region(block: Tree, builder: Builder) -> Region:
    head, props = _properties(block, builder)
    if "target" not in props or not isinstance(props["target"][0], str):
        raise builder.error(f"region {head} needs (:target name)", block)
    target = str(props.pop("target")[0])
    ranges = _numbers(*props.pop("ranges"), builder) if "ranges" in props else ()  # type: ignore[misc]
    yaw = _numbers(*props.pop("yaw_rotation"), builder) if "yaw_rotation" in props else ()  # type: ignore[misc]
    return Region(str(head), target, ranges, yaw, {k: v for k, (v, _) in props.items()})


def _original(text: str, token: Token) -> str:
    """The original-case text of a token, whitespace collapsed (the lexer saw a lower-cased copy)."""
    return " ".join(text[token.start_pos : token.end_pos].split())


def parse_bddl(text: str, source: str = "<string>") -> BddlProblem:
    """Parse a BDDL problem (LIBERO or BEHAVIOR); names are stored lower case."""
    tree = syntax_tree(text, source, "bddl_problem")
    check = Builder(source)
    parts: dict[str, Tree] = {}
    for child in tree.children[1:]:
        if child.data in parts:
            raise check.error(f"duplicate (:{child.data}) section", child)
        parts[child.data] = child
    if "problem_domain" not in parts or "goal" not in parts:
        missing = ":domain" if "problem_domain" not in parts else ":goal"
        raise check.error(f"problem has no ({missing} ...)", tree)
    requirements(parts.get("requirements"), check)
    fixtures: dict[str, str] = {}
    objects: dict[str, str] = {}
    if "fixtures" in parts:
        check.single_typed(parts["fixtures"].children[0], "fixture", fixtures)
    if "objects" in parts:
        check.single_typed(parts["objects"].children[0], "object", objects)
        for token in parts["objects"].children[0].children:
            if isinstance(token, Token) and str(token) in fixtures:
                raise check.error(f"{token} is declared both as a fixture and an object", token)
    language = None
    if "language" in parts:
        language = _original(text, parts["language"].children[0]) if parts["language"].children else ""
    regions = [_region(b, check) for b in parts["regions"].children] if "regions" in parts else []
    scene = {}
    for block in parts["scene_properties"].children if "scene_properties" in parts else ():
        head, props = _properties(block, check)
        scene[str(head)] = {k: v for k, (v, _) in props.items()}
    known = {*objects, *fixtures, *(r.qualified_name for r in regions)}
    builder = _BddlBuilder(source, known, {**fixtures, **objects})
    init: list[Atom] = []
    init_false: list[Atom] = []
    for item in parts["init"].children if "init" in parts else ():
        if item.data == "init_numeric":
            raise builder.error("numeric init values are not part of BDDL", item)
        target = init if item.data == "atom" else init_false
        target.append(builder.atom(item if item.data == "atom" else item.children[0], frozenset()))
    goal = builder.formula(parts["goal"].children[0], frozenset())
    interest = [str(t) for t in parts["obj_of_interest"].children] if "obj_of_interest" in parts else []
    domain_name = str(parts["problem_domain"].children[0])
    return BddlProblem(
        str(tree.children[0]), domain_name, language, regions, fixtures, objects, interest, init, goal,
        init_false, scene,
    )  # fmt: skip


def load_bddl(path: str | Path) -> BddlProblem:
    """Read and parse a BDDL problem file."""
    return parse_bddl(read_text(path), str(path))


def parse_bddl_domain(text: str, source: str = "<string>") -> Domain:
    """Parse a BDDL domain such as BEHAVIOR's domain_igibson.bddl (predicates only, PDDL syntax)."""
    domain = parse_domain(text, source)
    if domain.actions:
        name = next(iter(domain.actions))
        raise ParseError(f"a BDDL domain declares predicates only, found action {name!r}", source=source)
    return domain
