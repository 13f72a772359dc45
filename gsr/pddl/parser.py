"""PDDL reader: a lark LALR grammar, readable syntax errors and semantic checks with file:line:column.

Text is lower-cased (ASCII only, so positions do not move) before lexing because PDDL is
case-insensitive and the model stores lower-case names.
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
from collections.abc import Callable
from functools import cache
from pathlib import Path

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken
from lark.lexer import PatternStr

from gsr.errors import ParseError
from gsr.pddl.model import (
    NO_EFFECT,
    OBJECT,
    TRUE,
    Action,
    And,
    AndEffect,
    Atom,
    Axiom,
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

REQUIREMENTS = frozenset(
    {
        ":strips",
        ":typing",
        ":negative-preconditions",
        ":disjunctive-preconditions",
        ":equality",
        ":existential-preconditions",
        ":universal-preconditions",
        ":quantified-preconditions",
        ":conditional-effects",
        ":adl",
        ":action-costs",
        ":derived-predicates",
        ":negation",
    }
)
_STARTS = ["pddl_file", "domain", "problem", "formula_only", "atom_only", "bddl_problem"]
_LOWER = str.maketrans("ABCDEFGHIJKLMNOPQRSTUVWXYZ", "abcdefghijklmnopqrstuvwxyz")
_COMMENTS = re.compile(r";[^\n]*")
_TERMINAL_WORDS = {
    "NAME": "a name",
    "VAR": "a ?variable",
    "NUMBER": "a number",
    "REQUIREMENT": "a requirement such as :strips",
    "PROPERTY_KEY": "a property such as :target",
    "LANGUAGE_TEXT": "instruction text",
    "RAW": "a value",
    "$END": "end of file",
}

Node = Tree | Token


@cache
def _lark() -> Lark:
    """The compiled grammar (built once per process)."""
    grammar = Path(__file__).with_name("grammar.lark").read_text(encoding="utf-8")
    # Building the LALR tables costs ~0.2 s CPU per process; lark caches them in a file that records
    # the grammar's, options' and lark's hash and is rebuilt when any differs. Beside the package's
    # bytecode (not a shared temp dir, since the cache is a pickle); unwritable: built every time.
    # (lark logs a traceback when it cannot write the file, so an unwritable folder gets no cache at all.)
    cache_dir = Path(__file__).parent / "__pycache__"
    with contextlib.suppress(OSError):
        cache_dir.mkdir(exist_ok=True)
    cache_file = cache_dir / f"grammar.lark-py{sys.version_info[0]}{sys.version_info[1]}.cache"
    writable = os.access(cache_file if cache_file.exists() else cache_dir, os.W_OK)
    cache = str(cache_file) if writable else False
    return Lark(
        grammar, parser="lalr", start=_STARTS, propagate_positions=True, maybe_placeholders=False, cache=cache
    )


@cache
def _terminal_words() -> dict[str, str]:
    """Readable text for each terminal name: '(' for LPAR, 'a name' for NAME."""
    words = {t.name: f'"{t.pattern.value}"' for t in _lark().terminals if isinstance(t.pattern, PatternStr)}
    words.update(_TERMINAL_WORDS)
    return words


def _end_position(text: str) -> tuple[int, int]:
    """Line and column just after the last character."""
    return text.count("\n") + 1, len(text) - (text.rfind("\n") + 1) + 1


def _syntax_error(err: UnexpectedInput, text: str, source: str) -> ParseError:
    """Turn a lark exception into a ParseError with a readable 'expected' list."""
    words = _terminal_words()
    if isinstance(err, UnexpectedToken) and err.token.type != "$END":
        found = text[err.token.start_pos : err.token.end_pos]
        expected = err.accepts or err.expected  # accepts: the parser state's view, keywords included
        line, column = err.line, err.column
        known = err.token.type in words and words[err.token.type].startswith('"')
        kind = "unknown section or keyword" if found.startswith(":") and not known else "unexpected"
        message = f"{kind} {found!r}"
    elif isinstance(err, UnexpectedCharacters):
        match = re.match(r"[^\s()]+", text[err.pos_in_stream :])
        found = match.group(0) if match else text[err.pos_in_stream]
        expected = err.allowed or set()
        line, column = err.line, err.column
        kind = "unknown section or keyword" if found.startswith(":") else "unexpected"
        message = f"{kind} {found!r}"
    else:
        expected = err.expected if isinstance(err, UnexpectedToken | UnexpectedEOF) else set()
        line, column = _end_position(text)
        message = "unexpected end of file (missing ')'?)"
    shown = sorted({words.get(name, name) for name in expected if name not in ("WS", "COMMENT")})
    return ParseError(message, source=source, line=line, column=column, expected=tuple(shown))


def syntax_tree(text: str, source: str, start: str) -> Tree:
    """Parse ``text`` from grammar rule ``start``; every failure is a ParseError."""
    if not _COMMENTS.sub("", text).strip():
        raise ParseError("empty file", source=source, line=1, column=1)
    lowered = text.translate(_LOWER)
    try:
        return _lark().parse(lowered, start=start)
    except UnexpectedInput as err:
        raise _syntax_error(err, text, source) from None


def read_text(path: str | Path) -> str:
    """Read a UTF-8 file; a missing or unreadable file is a ParseError naming it."""
    try:
        return Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ParseError(f"cannot read file: {err}", source=str(path)) from None


class Builder:
    """Turns syntax trees into model objects, checking names and scopes as it goes.

    ``predicates``/``functions`` of None disable declaration checks (no domain known);
    ``is_object`` of None accepts any constant name.
    """

    allow_counting = False  # forn/forpairs are BDDL, not PDDL

    def __init__(
        self,
        source: str,
        *,
        types: dict[str, tuple[str, ...]] | None = None,
        predicates: dict[str, Predicate] | None = None,
        functions: dict[str, Predicate] | None = None,
        is_object: Callable[[str], bool] | None = None,
        free_variables: bool = False,
    ) -> None:
        self.source = source
        self.types = types
        self.predicates = predicates
        self.functions = functions
        self.is_object = is_object
        self.free_variables = free_variables

    # ------------------------------------------------------------ helpers

    def error(self, message: str, node: Node) -> ParseError:
        """A ParseError located at ``node``."""
        if isinstance(node, Token):
            return ParseError(message, source=self.source, line=node.line, column=node.column)
        meta = node.meta
        line = getattr(meta, "line", None)
        return ParseError(message, source=self.source, line=line, column=getattr(meta, "column", None))

    def check_type(self, name: str, node: Node) -> None:
        """Raise unless ``name`` is a declared type (when types are known)."""
        if self.types is not None and name != OBJECT and name not in self.types:
            raise self.error(f"undeclared type {name!r}", node)

    def typed_list(self, tree: Tree, *, lenient: bool = False) -> list[tuple[Token, tuple[str, ...]]]:
        """Group a flat ``a b - t c`` list into (name token, types); untyped names get ``object``;
        with ``lenient`` an undeclared type stands for ``object`` instead of being an error."""
        result: list[tuple[Token, tuple[str, ...]]] = []
        pending: list[Token] = []
        for child in tree.children:
            if isinstance(child, Token):
                pending.append(child)
                continue
            spec = child.children[0]
            if not pending:
                raise self.error("'-' with no names before it", child)
            names = tuple(str(t) for t in spec.children) if isinstance(spec, Tree) else (str(spec),)
            if lenient and self.types is not None:
                names = tuple(n if n == OBJECT or n in self.types else OBJECT for n in names)
            for name in names:
                self.check_type(name, spec)
            result.extend((token, names) for token in pending)
            pending = []
        result.extend((token, (OBJECT,)) for token in pending)
        return result

    def typed_vars(self, tree: Tree, *, declaration: bool = False) -> tuple[TypedVar, ...]:
        """Parameters of an action or quantifier. A predicate or function ``declaration`` only fixes
        the arity, as Fast Downward reads it: a repeated variable (logistics00's ``(in ?obj ?obj)``)
        is accepted there, and an undeclared type stands for ``object``; both are errors elsewhere."""
        seen: set[str] = set()
        params = []
        for token, types in self.typed_list(tree, lenient=declaration):
            if str(token) in seen and not declaration:
                raise self.error(f"duplicate parameter {token}", token)
            seen.add(str(token))
            params.append(TypedVar(str(token), types))
        return tuple(params)

    def single_typed(self, tree: Tree, what: str, into: dict[str, str]) -> None:
        """Fill ``into`` with name -> type from a typed name list (objects, constants, fixtures)."""
        for token, types in self.typed_list(tree):
            if len(types) != 1:
                raise self.error(f"{what} {token} needs one type, not (either ...)", token)
            if str(token) in into:
                raise self.error(f"duplicate {what} {token}", token)
            into[str(token)] = types[0]

    # ----------------------------------------------------------- formulas

    def term(self, token: Token, scope: frozenset[str], atom: Tree, index: int) -> str:
        """Check one argument of an atom: variables must be bound, names must be objects."""
        name = str(token)
        if token.type == "VAR":
            if name not in scope and not self.free_variables:
                raise self.error(f"unbound variable {name}", token)
        elif self.is_object is not None and not self.is_object(name):
            raise self.error(f"unknown object {name!r}", token)
        return name

    def atom(self, tree: Tree, scope: frozenset[str]) -> Atom:
        """An atom, checked against the declared predicates."""
        head, *args = tree.children
        name = str(head)
        if self.predicates is not None:
            declared = self.predicates.get(name)
            if declared is None:
                raise self.error(f"undeclared predicate {name!r}", head)
            if declared.arity != len(args):
                raise self.error(
                    f"predicate {name!r} takes {declared.arity} argument(s), got {len(args)}", head
                )
        return Atom(name, tuple(self.term(a, scope, tree, i) for i, a in enumerate(args)))

    def quantified(self, tree: Tree, scope: frozenset[str]) -> tuple[tuple[TypedVar, ...], Formula]:
        """Parameters and body of exists/forall."""
        params = self.typed_vars(tree.children[0])
        return params, self.formula(tree.children[1], scope | {p.name for p in params})

    def counting(self, tree: Tree, scope: frozenset[str]) -> Formula:
        """forn / forpairs / fornpairs: BDDL only."""
        kind = tree.data
        if not self.allow_counting or kind == "fornpairs":
            where = "a BDDL problem" if kind == "fornpairs" else "BDDL"
            raise self.error(f"{kind} is only allowed in {where}", tree)
        if kind == "forn":
            count_token, params_tree, body = tree.children
            params = self.typed_vars(params_tree)
            bound = scope | {p.name for p in params}
            return ForN(self.count(count_token), params, self.formula(body, bound))
        first_tree, second_tree, body = tree.children
        first, second = self.typed_vars(first_tree), self.typed_vars(second_tree)
        bound = scope | {p.name for p in first + second}
        return ForPairs(first, second, self.formula(body, bound))

    def count(self, token: Token) -> int:
        """The n of forn: a non-negative integer."""
        value = float(token)
        if value < 0 or value != int(value):
            raise self.error(f"count must be a non-negative integer, got {token}", token)
        return int(value)

    def formula(self, tree: Tree, scope: frozenset[str]) -> Formula:
        """A goal description (precondition, goal, when-condition)."""
        kind = tree.data
        if kind == "atom":
            return self.atom(tree, scope)
        if kind == "empty":
            return TRUE
        if kind == "equals":
            left, right = (self.term(t, scope, tree, i) for i, t in enumerate(tree.children))
            return Equals(left, right)
        if kind == "not_gd":
            return Not(self.formula(tree.children[0], scope))
        if kind == "and_gd":
            return And(tuple(self.formula(c, scope) for c in tree.children))
        if kind == "or_gd":
            return Or(tuple(self.formula(c, scope) for c in tree.children))
        if kind == "imply":
            return Imply(self.formula(tree.children[0], scope), self.formula(tree.children[1], scope))
        if kind == "exists":
            return Exists(*self.quantified(tree, scope))
        if kind == "forall":
            return Forall(*self.quantified(tree, scope))
        return self.counting(tree, scope)

    # ------------------------------------------------------------ effects

    def function_term(self, tree: Tree, scope: frozenset[str]) -> tuple[str, tuple[str, ...]]:
        """``(total-cost)`` or ``(road-length ?a ?b)``: checked against the declared functions."""
        head, *args = tree.children
        name = str(head)
        if self.functions is not None:
            declared = self.functions.get(name)
            if declared is None:
                raise self.error(f"undeclared function {name!r}", head)
            if declared.arity != len(args):
                raise self.error(
                    f"function {name!r} takes {declared.arity} argument(s), got {len(args)}", head
                )
        return name, tuple(self.term(a, scope, tree, i) for i, a in enumerate(args))

    def effect(self, tree: Tree, scope: frozenset[str]) -> Effect:
        """An action effect."""
        kind = tree.data
        if kind == "atom":
            return Literal(self.atom(tree, scope))
        if kind == "not_effect":
            return Literal(self.atom(tree.children[0], scope), negated=True)
        if kind == "and_effect":
            return AndEffect(tuple(self.effect(c, scope) for c in tree.children))
        if kind == "empty":
            return NO_EFFECT
        if kind == "forall_effect":
            params = self.typed_vars(tree.children[0])
            return ForallEffect(params, self.effect(tree.children[1], scope | {p.name for p in params}))
        if kind == "when":
            return When(self.formula(tree.children[0], scope), self.effect(tree.children[1], scope))
        function, args = self.function_term(tree.children[0], scope)
        amount_tree = tree.children[1]
        if amount_tree.data == "number":
            amount: float | str = float(amount_tree.children[0])
        else:
            name, amount_args = self.function_term(amount_tree, scope)
            amount = f"({' '.join((name, *amount_args))})"
        return Increase(function, args, amount)


def _sections(tree: Tree, builder: Builder, repeatable: frozenset[str]) -> dict[str, list[Tree]]:
    """Children grouped by kind; a repeated section (other than ``repeatable``) is an error."""
    found: dict[str, list[Tree]] = {}
    for child in tree.children[1:]:
        if child.data in found and child.data not in repeatable:
            raise builder.error(f"duplicate (:{child.data.replace('_', ' ')}) section", child)
        found.setdefault(child.data, []).append(child)
    return found


def requirements(tree: Tree | None, builder: Builder) -> tuple[str, ...]:
    """The requirement flags of a (:requirements ...) section, all of them supported ones."""
    if tree is None:
        return ()
    for token in tree.children:
        if str(token) not in REQUIREMENTS:
            raise builder.error(f"unsupported requirement {token}", token)
    return tuple(dict.fromkeys(str(t) for t in tree.children))


def _declare_types(tree: Tree, builder: Builder, types: dict[str, tuple[str, ...]]) -> None:
    """Fill ``types`` from (:types ...); a parent never declared itself becomes a child of object.

    A type listed more than once gets every parent it is listed under (IPC storage lists ``area``
    under ``object`` and under ``surface``; Fast Downward accepts that); a type that is its own
    ancestor is an error.
    """
    explicit: set[str] = set()
    implicit: set[str] = set()
    tokens: dict[str, Token] = {}
    builder.types = None  # parents may be declared later in the same list
    for token, parents in builder.typed_list(tree):
        name = str(token)
        tokens.setdefault(name, token)
        if name in parents and name != OBJECT:  # tidybot declares "object - object"
            raise builder.error(f"type {name!r} cannot be its own parent", token)
        explicit.add(name)
        if name == OBJECT:
            continue
        if name in types:
            merged = tuple(dict.fromkeys((*types[name], *parents)))
            if len(merged) > 1:
                merged = tuple(p for p in merged if p != OBJECT) or (OBJECT,)
            parents = merged
        types[name] = parents
        for parent in parents:
            if parent != OBJECT and parent not in explicit:
                implicit.add(parent)
    for parent in implicit - explicit:
        types[parent] = (OBJECT,)
    for name in types:
        if name != OBJECT and name in _ancestors(types, name):
            raise builder.error(f"type {name!r} is its own ancestor (cyclic :types)", tokens.get(name, tree))


def _ancestors(types: dict[str, tuple[str, ...]], name: str) -> set[str]:
    """The strict ancestors of a type."""
    seen: set[str] = set()
    stack = list(types.get(name, ()))
    while stack:
        t = stack.pop()
        if t not in seen:
            seen.add(t)
            stack.extend(types.get(t, ()))
    return seen


def build_domain(tree: Tree, source: str) -> Domain:
    """A Domain from a ``domain`` syntax tree."""
    builder = Builder(source)
    name = str(tree.children[0])
    parts = _sections(tree, builder, frozenset({"action", "derived"}))
    domain = Domain(name=name, requirements=requirements(_first(parts, "requirements"), builder))
    if "types" in parts:
        _declare_types(parts["types"][0].children[0], builder, domain.types)
    builder.types = domain.types
    if "constants" in parts:
        builder.single_typed(parts["constants"][0].children[0], "constant", domain.constants)
    for decl in parts["predicates"][0].children if "predicates" in parts else ():
        _declare(decl, builder, domain.predicates, "predicate")
    for item in parts["functions"][0].children if "functions" in parts else ():
        if item.data == "function_type":
            if str(item.children[0]) != "number":
                raise builder.error("only numeric functions (- number) are supported", item)
        else:
            _declare(item, builder, domain.functions, "function")
    builder.predicates, builder.functions = domain.predicates, domain.functions
    builder.is_object = domain.constants.__contains__
    for action_tree in parts.get("action", ()):
        action = _build_action(action_tree, builder)
        if action.name in domain.actions:
            raise builder.error(f"duplicate action {action.name!r}", action_tree.children[0])
        domain.actions[action.name] = action
    for derived_tree in parts.get("derived", ()):
        domain.axioms.append(_build_axiom(derived_tree, builder, domain))
    return domain


def _build_axiom(tree: Tree, builder: Builder, domain: Domain) -> Axiom:
    """One ``(:derived (p ?x - t ...) body)`` rule; ``p`` must be a declared predicate of that arity
    that no action changes."""
    head_tree, body_tree = tree.children
    head = head_tree.children[0]
    name = str(head)
    params = builder.typed_vars(head_tree.children[1])
    declared = domain.predicates.get(name)
    if declared is None:
        raise builder.error(f"derived predicate {name!r} is not declared in (:predicates ...)", head)
    if declared.arity != len(params):
        raise builder.error(f"predicate {name!r} takes {declared.arity} argument(s), got {len(params)}", head)
    for action in domain.actions.values():
        if name in _effect_predicates(action.effect):
            raise builder.error(f"derived predicate {name!r} is changed by action {action.name!r}", head)
    body = builder.formula(body_tree, frozenset(p.name for p in params))
    return Axiom(name, params, body)


def _effect_predicates(effect: Effect) -> set[str]:
    """Predicates an effect adds or deletes."""
    if isinstance(effect, Literal):
        return {effect.atom.predicate}
    if isinstance(effect, AndEffect):
        return set().union(*(_effect_predicates(p) for p in effect.parts))
    if isinstance(effect, (When, ForallEffect)):
        return _effect_predicates(effect.effect)
    return set()


def _first(parts: dict[str, list[Tree]], kind: str) -> Tree | None:
    found = parts.get(kind)
    return found[0] if found else None


def _declare(tree: Tree, builder: Builder, into: dict[str, Predicate], what: str) -> None:
    head = tree.children[0]
    if str(head) in into:
        raise builder.error(f"duplicate {what} {str(head)!r}", head)
    into[str(head)] = Predicate(str(head), builder.typed_vars(tree.children[1], declaration=True))


def _build_action(tree: Tree, builder: Builder) -> Action:
    head, *parts = tree.children
    seen: dict[str, Tree] = {}
    for part in parts:
        if part.data in seen:
            raise builder.error(f"duplicate :{part.data.split('_')[0]} in action {head}", part)
        seen[part.data] = part
    params = builder.typed_vars(seen["parameters"].children[0]) if "parameters" in seen else ()
    scope = frozenset(p.name for p in params)
    pre = builder.formula(seen["precondition"].children[0], scope) if "precondition" in seen else TRUE
    eff = builder.effect(seen["effect_part"].children[0], scope) if "effect_part" in seen else NO_EFFECT
    return Action(str(head), params, pre, eff)


def build_problem(tree: Tree, source: str, domain: Domain | None) -> Problem:
    """A Problem from a ``problem`` syntax tree, checked against ``domain`` when given."""
    builder = Builder(source)
    parts = _sections(tree, builder, frozenset())
    problem = Problem(name=str(tree.children[0]), domain_name="")
    if "problem_domain" not in parts:
        raise builder.error("problem has no (:domain ...)", tree)
    domain_token = parts["problem_domain"][0].children[0]
    problem.domain_name = str(domain_token)
    if domain is not None and domain.name != problem.domain_name:
        raise builder.error(
            f"problem is for domain {problem.domain_name!r}, not {domain.name!r}", domain_token
        )
    problem.requirements = requirements(_first(parts, "requirements"), builder)
    if domain is not None:
        builder.types = domain.types
    if "objects" in parts:
        builder.single_typed(parts["objects"][0].children[0], "object", problem.objects)
    if domain is not None:
        known = {**domain.constants, **problem.objects}
        builder.predicates, builder.functions, builder.is_object = (
            domain.predicates,
            domain.functions,
            known.__contains__,
        )
    init: set[Atom] = set()
    negated: list[tuple[Atom, Tree]] = []
    for item in parts["init"][0].children if "init" in parts else ():
        if item.data == "atom":
            init.add(builder.atom(item, frozenset()))
        elif item.data == "init_numeric":
            function, args = builder.function_term(item.children[0], frozenset())
            problem.init_numeric[Atom(function, args)] = float(item.children[1])
        else:  # (not (p ...)): redundant under the closed world (Fast Downward accepts it too)
            negated.append((builder.atom(item.children[0], frozenset()), item))
    for atom, item in negated:
        if atom in init:
            raise builder.error(f"{atom} is both true and false in :init", item)
    problem.init = frozenset(init)
    if "goal" not in parts:
        raise builder.error("problem has no (:goal ...)", tree)
    problem.goal = builder.formula(parts["goal"][0].children[0], frozenset())
    if "metric" in parts:
        problem.metric = _metric(parts["metric"][0], builder)
    return problem


def _metric(tree: Tree, builder: Builder) -> tuple[str, str]:
    direction, expression = tree.children
    if str(direction) not in ("minimize", "maximize"):
        raise builder.error(f"metric must minimize or maximize, not {direction}", direction)
    if expression.data != "f_head" or len(expression.children) != 1:
        raise builder.error(
            "only a metric over a 0-ary function such as (total-cost) is supported", expression
        )
    builder.function_term(expression, frozenset())
    return str(direction), str(expression.children[0])


# ---------------------------------------------------------------- public API


def parse_domain(text: str, source: str = "<string>") -> Domain:
    """Parse a PDDL domain."""
    return build_domain(syntax_tree(text, source, "domain"), source)


def parse_problem(text: str, source: str = "<string>", domain: Domain | None = None) -> Problem:
    """Parse a PDDL problem; with ``domain``, check predicates, arities, types and objects against it."""
    return build_problem(syntax_tree(text, source, "problem"), source, domain)


def parse_pddl(text: str, source: str = "<string>") -> Domain | Problem:
    """Parse a PDDL domain or problem, whichever the text holds."""
    tree = syntax_tree(text, source, "pddl_file").children[0]
    return build_domain(tree, source) if tree.data == "domain" else build_problem(tree, source, None)


def load_domain(path: str | Path) -> Domain:
    """Read and parse a PDDL domain file."""
    return parse_domain(read_text(path), str(path))


def load_problem(path: str | Path, domain: Domain | None = None) -> Problem:
    """Read and parse a PDDL problem file (checked against ``domain`` when given)."""
    return parse_problem(read_text(path), str(path), domain)


def load_pddl(path: str | Path) -> Domain | Problem:
    """Read and parse a PDDL domain or problem file."""
    return parse_pddl(read_text(path), str(path))


class _FormulaBuilder(Builder):
    allow_counting = True


def parse_formula(text: str, source: str = "<string>") -> Formula:
    """Parse one formula such as ``(and (on a b) (not (open d)))``; free variables are allowed."""
    tree = syntax_tree(text, source, "formula_only").children[0]
    return _FormulaBuilder(source, free_variables=True).formula(tree, frozenset())


def parse_atom(text: str, source: str = "<string>") -> Atom:
    """Parse one atom such as ``(on a b)``."""
    tree = syntax_tree(text, source, "atom_only").children[0]
    return Builder(source, free_variables=True).atom(tree, frozenset())
