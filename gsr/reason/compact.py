"""The compact, model-friendly text of a step query: one token per object, predicate and action.

The human-readable prompt (:mod:`gsr.reason.prompt`, ~1,000 tokens) suits chat models. A small model
trained from scratch learns far faster from this word-level form (~60-200 tokens)::

    S: movable o7 o2 o12 supporter o3 on o7 o3 on o2 o3 hand_empty
    G: F in o7 o12 T on o2 o3
    H: pick o2 o9 place_on o2 o3
    A: pick o7 o3 <eos>

- ``S:`` the state: every true atom except the ones the text need not say (``next``, ``has_color``,
  zero ``cube_count``); a unary static predicate is written once before all its objects.
- ``G:`` the goal, grounded over the scene (quantifiers expanded, static atoms such as colours
  evaluated); a conjunction of literals is written literal by literal, each marked ``T`` (holds now)
  or ``F`` (not yet); anything else is written in prefix form with parentheses.
- ``H:`` the last :data:`HISTORY` actions; ``A:`` the cue; the answer is ``action arg ... <eos>``
  or ``done <eos>``.

Object names become placeholders ``o0`` .. ``o{MAX_OBJECTS-1}`` through a :class:`Naming` (a random
permutation in training, sorted names at inference), so a model never memorises names and works on
scenes with names it never saw. The same functions build the training rows (:mod:`gsr.train.compact`)
and the transformers backend's queries, so training and inference see identical tokens.
"""

from __future__ import annotations

import itertools
import random
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from gsr.errors import GSRError
from gsr.facts import state_from_graph
from gsr.pddl.model import And, Atom, Domain, Equals, Exists, Forall, Formula, Imply, Not, Or
from gsr.scene_graph import SceneGraph
from gsr.semantics import compile_domain, holds
from gsr.state import State
from gsr.step import Goal, Step

#: Format versions the backend reads (the marker names the one a model was trained in). Version 2
#: adds the focus facts after each unmet goal literal and puts the goal last; version 3 (the recipe's)
#: also lists the facts in which a literal's object is a later argument (what stands on or in it).
FORMATS = {"gsr-compact-1": 1, "gsr-compact-2": 2, "gsr-compact-3": 3}
MARKER = "gsr_compact.json"  # written beside the weights of a compact-format model
MAX_OBJECTS = 64
HISTORY = 4
EOS, PAD, UNK = "<eos>", "<pad>", "<unk>"
DONE_TOKEN = "done"
STRUCTURE = ("S:", "G:", "H:", "A:", "T", "F", "(", ")", "and", "or", "not", "imply", "=", ":")
_DROPPED = frozenset({"next", "has_color"})


class CompactError(GSRError):
    """A scene or answer the compact format cannot express (too many objects, unknown tokens)."""


def vocabulary(domain: Domain) -> list[str]:
    """Every token of the format for ``domain`` (special tokens first; order fixes the token ids)."""
    words = [PAD, EOS, UNK, *STRUCTURE, DONE_TOKEN]
    words += sorted(domain.predicates)
    words += sorted(a for a in domain.actions if a not in domain.predicates)
    words += sorted(domain.constants)
    words += [f"o{i}" for i in range(MAX_OBJECTS)]
    out: list[str] = []
    for w in words:
        if w not in out:
            out.append(w)
    return out


@dataclass(frozen=True)
class Naming:
    """Object name <-> placeholder token, in both directions."""

    to_token: dict[str, str]

    @property
    def to_name(self) -> dict[str, str]:
        """Placeholder token -> object name."""
        return {t: n for n, t in self.to_token.items()}

    @classmethod
    def make(cls, names: Iterable[str], rng: random.Random | None = None) -> Naming:
        """Sorted names -> o0, o1, ... (inference); a random permutation of them when ``rng`` is given (training)."""
        names = sorted(set(names))
        if len(names) > MAX_OBJECTS:
            raise CompactError(f"the scene has {len(names)} objects; the compact format holds {MAX_OBJECTS}")
        # a random order of o0..o{n-1}: every placeholder of a small scene is trained often
        slots = rng.sample(range(len(names)), len(names)) if rng else range(len(names))
        return cls({n: f"o{i}" for n, i in zip(names, slots, strict=False)})

    def token(self, name: str) -> str:
        """The token of an object or constant name (constants stand for themselves)."""
        return self.to_token.get(name, name)


def scene_objects(state: State, domain: Domain) -> list[str]:
    """The names that get placeholders: the state's objects that are not domain constants."""
    return sorted(n for n in state.objects if n not in domain.constants)


def _fluents(domain: Domain) -> frozenset[str]:
    return frozenset(compile_domain(domain).fluents)


def state_tokens(state: State, domain: Domain, naming: Naming) -> list[str]:
    """``S:`` part: the atoms, unary statics grouped, in a fixed order of predicates and placeholders."""
    order = {p: i for i, p in enumerate(sorted(domain.predicates))}
    fluents = _fluents(domain)

    def key(a: Atom) -> tuple:
        return (order.get(a.predicate, 99), [_slot(naming.token(x)) for x in a.args])

    atoms = sorted(
        (
            a
            for a in state.atoms
            if a.predicate not in _DROPPED and not (a.predicate == "cube_count" and a.args[1:] == ("n0",))
        ),
        key=key,
    )
    out = ["S:"]
    for pred, group in itertools.groupby(atoms, key=lambda a: a.predicate):
        group = list(group)
        if len(group[0].args) == 1 and pred not in fluents:
            out += [pred, *(naming.token(a.args[0]) for a in group)]
        else:
            for a in group:
                out += [pred, *(naming.token(x) for x in a.args)]
    return out


def _slot(token: str) -> int:
    return int(token[1:]) if token.startswith("o") and token[1:].isdigit() else -1


def ground_goal(formula: Formula, state: State, domain: Domain) -> Formula:
    """The goal without quantifiers, static atoms evaluated in ``state``, simplified."""
    fluents = _fluents(domain)
    objects = dict(domain.constants) | dict(state.objects)

    def bindings(params) -> list[dict[str, str]]:
        pools = [[o for o, t in objects.items() if domain.is_subtype(t, p.types)] for p in params]
        return [
            {p.name: o for p, o in zip(params, combo, strict=True)} for combo in itertools.product(*pools)
        ]

    def sub(f: Formula, b: dict[str, str]) -> Formula | bool:
        if isinstance(f, Atom):
            atom = Atom(f.predicate, tuple(b.get(x, x) for x in f.args))
            if atom.predicate not in fluents:
                return atom in state.atoms
            return atom
        if isinstance(f, Equals):
            return b.get(f.left, f.left) == b.get(f.right, f.right)
        if isinstance(f, Not):
            inner = sub(f.formula, b)
            return (not inner) if isinstance(inner, bool) else Not(inner)
        if isinstance(f, Imply):
            return sub(Or((Not(f.condition), f.then)), b)
        if isinstance(f, And | Or | Forall | Exists):
            parts = (
                [sub(p, b) for p in f.parts]
                if isinstance(f, And | Or)
                else [sub(f.body, b | x) for x in bindings(f.params)]
            )
            return _junction(parts, And if isinstance(f, And | Forall) else Or)
        raise CompactError(f"the compact format cannot express the goal part {type(f).__name__}")

    result = sub(formula, {})
    if result is True:
        return And(())
    if result is False:
        return Or(())
    return result


def _flatten(parts: list, kind: type) -> list:
    out = []
    for p in parts:
        out.extend(p.parts if isinstance(p, kind) else [p])
    return out


def _junction(parts: list[Formula | bool], kind: type[And] | type[Or]) -> Formula | bool:
    """``kind`` (And or Or) over simplified parts: a part equal to the absorbing constant (False for And,
    True for Or) decides it, the neutral ones drop out, nested ``kind`` flattens, one part stands alone."""
    neutral = kind is And
    if any(p is (not neutral) for p in parts):
        return not neutral
    kept = _flatten([p for p in parts if p is not neutral], kind)
    return kept[0] if len(kept) == 1 else (kind(tuple(kept)) if kept else neutral)


def goal_tokens(
    formula: Formula, state: State, domain: Domain, naming: Naming, version: int = 1
) -> list[str]:
    """``G:`` part: marked literals of a conjunctive goal, else the grounded formula in prefix form.

    From version 2 on, a literal that does not hold yet is followed by ``:`` and the current facts
    about its objects (where each one is, whether it is held, open or openable), so what the next
    step needs stands next to the literal it serves. From version 3 on, the focus facts also include
    the ones naming the object in a later position (what is on or in it: what blocks it)."""
    grounded = ground_goal(formula, state, domain)
    parts = grounded.parts if isinstance(grounded, And) else (grounded,)
    out = ["G:"]
    if all(isinstance(p, Atom) or (isinstance(p, Not) and isinstance(p.formula, Atom)) for p in parts):
        for p in parts:
            atom = p.formula if isinstance(p, Not) else p
            ok = holds(domain, p, state)
            out.append("T" if ok else "F")
            out += (["not"] if isinstance(p, Not) else []) + [atom.predicate]
            out += [naming.token(x) for x in atom.args]
            if version >= 2 and not ok:
                out += _focus(atom.args, state, naming, anywhere=version >= 3)
        return out
    return out + _prefix(grounded, naming)


_FOCUS = ("on", "in", "holding", "open", "turned_on", "openable", "switchable")


def _focus(args: Sequence[str], state: State, naming: Naming, anywhere: bool = False) -> list[str]:
    """``:`` and the atoms of :data:`_FOCUS` whose first argument (any argument when ``anywhere``)
    is one of ``args``; an atom is written once."""
    out = [":"]
    seen: set[Atom] = set()
    for arg in args:
        mine = [
            a
            for a in state.atoms
            if a.predicate in _FOCUS
            and a not in seen
            and (arg in a.args if anywhere else a.args[:1] == (arg,))
        ]
        seen.update(mine)
        for atom in sorted(mine, key=lambda a: (a.predicate, a.args)):
            out += [atom.predicate, *(naming.token(x) for x in atom.args)]
    return out


def _prefix(f: Formula, naming: Naming) -> list[str]:
    if isinstance(f, Atom):
        return ["(", f.predicate, *(naming.token(x) for x in f.args), ")"]
    if isinstance(f, Not):
        return ["(", "not", *_prefix(f.formula, naming), ")"]
    if isinstance(f, And | Or):
        head = "and" if isinstance(f, And) else "or"
        return ["(", head, *(t for p in f.parts for t in _prefix(p, naming)), ")"]
    raise CompactError(f"the compact format cannot express the goal part {type(f).__name__}")


def action_tokens(step: Step | None, naming: Naming) -> list[str]:
    """An action as tokens (``done`` for None)."""
    if step is None:
        return [DONE_TOKEN]
    return [step.action, *(naming.token(x) for x in step.args)]


def context_tokens(
    state: State,
    domain: Domain,
    goal: Goal | Formula | None,
    history: Sequence[Step],
    naming: Naming,
    version: int = 1,
) -> list[str]:
    """The whole query, ending with the ``A:`` cue (version 1: S G H A; version 2: S H G A)."""
    out = state_tokens(state, domain, naming)
    goal_part = []
    if goal is not None:
        formula = goal.formula if isinstance(goal, Goal) else goal
        goal_part = goal_tokens(formula, state, domain, naming, version)
    history_part = ["H:"]
    for step in list(history)[-HISTORY:] if HISTORY else []:
        history_part += action_tokens(step, naming)
    out += goal_part + history_part if version == 1 else history_part + goal_part
    out.append("A:")
    return out


def query_tokens(
    graph: SceneGraph,
    domain: Domain,
    goal: Goal | Formula | None,
    history: Sequence[Step],
    version: int = 1,
) -> tuple[list[str], Naming]:
    """Inference-side context: the graph's state with sorted-name placeholders."""
    state = state_from_graph(graph, domain)
    naming = Naming.make(scene_objects(state, domain))
    return context_tokens(state, domain, goal, history, naming, version), naming


def answer_step(tokens: Sequence[str], naming: Naming, domain: Domain) -> Step | None:
    """The step an answer names (None for ``done``); CompactError for anything else."""
    words = [t for t in tokens if t not in (EOS, PAD)]
    if words == [DONE_TOKEN]:
        return None
    if not words or words[0] not in domain.actions:
        raise CompactError(f"not an action: {' '.join(words) or '(empty)'}")
    names = naming.to_name
    args = []
    for w in words[1:]:
        if w in names:
            args.append(names[w])
        elif w in domain.constants:
            args.append(w)
        else:
            raise CompactError(f"unknown object token {w!r} in {' '.join(words)}")
    return Step(words[0], tuple(args))


def build_tokenizer(domain: Domain):
    """A word-level ``PreTrainedTokenizerFast`` over :func:`vocabulary` (whitespace-separated tokens)."""
    from tokenizers import Tokenizer, decoders, models, pre_tokenizers
    from transformers import PreTrainedTokenizerFast

    vocab = {w: i for i, w in enumerate(vocabulary(domain))}
    tok = Tokenizer(models.WordLevel(vocab, unk_token=UNK))
    tok.pre_tokenizer = pre_tokenizers.WhitespaceSplit()
    tok.decoder = decoders.WordPiece(prefix="##", cleanup=False)
    return PreTrainedTokenizerFast(
        tokenizer_object=tok, eos_token=EOS, pad_token=PAD, unk_token=UNK, clean_up_tokenization_spaces=False
    )
