"""``ground(instruction, graph) -> Goal``: the embedded, rule-based goal interpreter."""

from __future__ import annotations

from lark import Tree
from lark.visitors import CollapseAmbiguities

from gsr.facts import graph_objects
from gsr.language.build import Interpreter
from gsr.language.errors import GroundingError
from gsr.language.fallback import clarifying_error, match_goal
from gsr.language.goals import goal_formula
from gsr.language.lexicon import build_lexicon
from gsr.language.parse import parse_tokens, tokenize
from gsr.language.refs import Resolver
from gsr.pddl.model import Domain, Formula
from gsr.pddl.writer import write_formula
from gsr.resources import load_builtin_domain
from gsr.scene_graph import SceneGraph
from gsr.step import Goal

#: Most parse readings interpreted for one instruction (Earley keeps every reading).
MAX_READINGS = 64


def _readings(tree: Tree) -> list[Tree]:
    """Every reading of an ambiguous parse (at most MAX_READINGS)."""
    if not any(t.data == "_ambig" for t in tree.iter_subtrees()):
        return [tree]
    return CollapseAmbiguities().transform(tree)[:MAX_READINGS]


def ground(instruction: str, graph: SceneGraph, domain: Domain | None = None) -> Goal:
    """The goal an instruction asks for, as a PDDL formula over the graph's node ids.

    Raises GroundingError naming the unknown words, the place the parse failed, or the candidate
    objects of an ambiguous or unmatched reference. Every reading of the sentence is interpreted; when
    the readings that can be grounded disagree, that is an ambiguity error too (never a silent guess).
    """
    if not isinstance(instruction, str) or not instruction.strip():
        raise GroundingError("empty instruction")
    domain = domain or load_builtin_domain("tabletop")
    lex = build_lexicon(graph)
    try:
        tokens = tokenize(instruction, lex)
        tree = parse_tokens(tokens, instruction)
    except GroundingError as exc:
        # the second route: a scored match over the simple goals the scene allows, else a clarifying
        # error naming the unknown words and the closest known ones

        match = match_goal(instruction, lex)
        if match is not None:
            return Goal(formula=match.formula, text=instruction)
        raise clarifying_error(exc, instruction, lex) from None
    types = graph_objects(graph, domain)
    goals: list[Formula] = []
    errors: list[GroundingError] = []
    shapes: set[tuple[str, ...]] = set()  # the clause kinds of the readings that gave a goal
    failed_shapes: list[tuple[str, ...]] = []  # ... and of each failed reading, in the order of errors
    for reading in _readings(tree):
        shape = tuple(c.data for c in reading.children if isinstance(c, Tree) and c.data.endswith("_cmd"))
        interp = Interpreter(Resolver(graph, lex.entities, domain))
        try:
            formula = goal_formula(interp.run(reading), interp.resolver, types)
        except GroundingError as exc:
            errors.append(exc)
            failed_shapes.append(shape)
            continue
        except (
            AssertionError,
            StopIteration,
            KeyError,
            IndexError,
            ValueError,
            AttributeError,
            TypeError,
        ) as exc:
            # a reading the interpreter has no rule for (a grammar path without semantics): not this reading
            errors.append(GroundingError(f"cannot interpret {instruction!r} ({type(exc).__name__}: {exc})"))
            failed_shapes.append(shape)
            continue
        shapes.add(shape)
        if formula not in goals:
            goals.append(formula)
    if not goals:
        raise _best_error(errors)
    unsure = [
        e for e, shape in zip(errors, failed_shapes, strict=True) if _ambiguous(e) and shape not in shapes
    ]
    if unsure:
        # a reading with other clause kinds that fails only because a reference is ambiguous might be the
        # meant one ("get the cup inside the box": put the cup in the box, or pick up the cup that is in
        # it): never pick silently between verb senses (a PP read as a restriction is not enough)
        raise unsure[0]
    if len(goals) > 1:
        readings = "; ".join(write_formula(g) for g in goals[:4])
        raise GroundingError(f"{instruction!r} has {len(goals)} readings with different goals: {readings}")
    return Goal(formula=goals[0], text=instruction)


def _ambiguous(exc: GroundingError) -> bool:
    return bool(exc.candidates) and "ambiguous" in exc.message


def _best_error(errors: list[GroundingError]) -> GroundingError:
    """The most informative error among the readings: ambiguity first, then unmatched references."""
    for exc in errors:
        if exc.candidates and "ambiguous" in exc.message:
            return exc
    for exc in errors:
        if exc.phrase:
            return exc
    return errors[0]
