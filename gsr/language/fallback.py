"""The second route when the grammar fails: a scored matcher over goal candidates, else a clarifying error.

When an instruction has words outside the lexicon or a shape the grammar does not accept,
:func:`match_goal` instantiates the simple goals the scene allows (put one object, or all objects of a
kind and colour, in or on one place; open, close, switch on or off one object) and scores each against
the instruction's known content words: the object side (before the last ``in``/``on``/``to``) must
describe the objects, the destination side the place, and every content word counts, unknown words
against the match. The best candidate is taken only when its confidence reaches :data:`THRESHOLD`
and no other candidate scores as high; otherwise :func:`clarifying_error` names the unknown words
with the closest known ones (``'wigle' (did you mean: wiggle?)``).
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass

from gsr.language.errors import GroundingError
from gsr.language.lexicon import Entity, Lexicon
from gsr.language.parse import CONTRACTIONS
from gsr.language.words import FILLER
from gsr.pddl.model import And, Atom, Formula, Not

#: Least confidence (explained content words / all content words, times the fit of the match).
THRESHOLD = 0.75
#: Word classes that carry content (what the objects and places are).
_CONTENT = {"NOUN", "COLOR", "COLORNOUN", "NAME", "ENTITY", "POS", "SIDE"}
_DEST_PREP = {"IN", "INSIDE", "ON", "TO"}
#: Classes that change the meaning in ways the matcher cannot follow: never guess over them.
_BLOCKING = {
    "NOT",
    "EXCEPT",
    "NUM",
    "ONE",
    "DIFFERENT",
    "SAME",
    "CORRESPONDING",
    "BY",
    "NO",
    "OTHER",
    "UNDER",
}


@dataclass(frozen=True, slots=True)
class Match:
    """A candidate goal and its confidence."""

    formula: Formula
    confidence: float
    text: str


def _words(instruction: str, lex: Lexicon) -> list[tuple[str, str, str]]:
    """(word, class, value) per word; class ``?`` for unknown words."""
    text = instruction.lower().replace("\u2019", "'")
    for pattern, full in CONTRACTIONS:
        text = pattern.sub(full, text)
    for mark in ",.?!;:":
        text = text.replace(mark, " ")
    out = []
    for raw in text.split():
        raw = raw.strip("\"'()")
        if not raw or raw in FILLER:
            continue
        hit = lex.lookup((raw,))
        if hit is None and raw.endswith("s"):
            hit = lex.lookup((raw[:-1],))
        if hit is None and raw in lex.entities:
            hit = ("ENTITY", raw)
        out.append((raw, hit[0], hit[1].removesuffix("#pl")) if hit else (raw, "?", raw))
    return out


def _fit(entity: Entity, side: list[tuple[str, str, str]]) -> float:
    """How well the words describe the entity: +1 per fitting word, -1 per contradicting word."""
    score = 0.0
    for _, cls, value in side:
        if cls == "ENTITY":
            score += 3 if value == entity.id else -3
        elif cls in ("NOUN", "COLORNOUN"):
            score += 1 if (value in entity.kinds or value in entity.broader or value in entity.words) else -2
        elif cls == "COLOR":
            score += 1 if value in entity.colors else -2
        elif cls == "NAME":
            score += 0.5 if value in entity.words else -0.5
        elif cls in ("POS", "SIDE"):
            score += 0.5 if value in entity.positions else -0.5
    return score


def _best(entities: list[Entity], side: list[tuple[str, str, str]]) -> tuple[list[Entity], float]:
    scored = [(e, _fit(e, side)) for e in entities]
    if not scored:
        return [], 0.0
    top = max(s for _, s in scored)
    return [e for e, s in scored if s == top], top


def match_goal(instruction: str, lex: Lexicon) -> Match | None:
    """The best simple goal for the instruction, if confident enough; None otherwise."""
    words = _words(instruction, lex)
    classes = {c for _, c, _ in words}
    if classes & _BLOCKING or not classes & _CONTENT:
        return None
    content = [w for w in words if w[1] in _CONTENT or w[1] == "?"]
    unknown = sum(1 for w in content if w[1] == "?")
    known = [w for w in content if w[1] != "?"]
    if not known:
        return None
    ents = [e for e in lex.entities.values()]
    prep = max((i for i, w in enumerate(words) if w[1] in _DEST_PREP), default=None)
    if prep is not None:  # a placement: objects before the preposition, the place after it
        obj_side = [w for w in words[:prep] if w[1] in _CONTENT]
        dest_side = [w for w in words[prep + 1 :] if w[1] in _CONTENT]
        if not obj_side or not dest_side:
            return None
        places = [e for e in ents if e.affordances & {"container", "supporter"}]
        dests, dest_score = _best(places, dest_side)
        movable = [e for e in ents if "movable" in e.affordances and e.id not in {d.id for d in dests}]
        objs, obj_score = _best(movable, obj_side)
        plural = any(c in ("ALL", "EACH", "BOTH", "EVERYTHING") for _, c, _ in words) or any(
            w.endswith("s") and c == "NOUN" for w, c, _ in obj_side
        )
        if len(dests) != 1 or not objs or (len(objs) > 1 and not plural) or dest_score <= 0 or obj_score <= 0:
            return None
        pred = "in" if "container" in dests[0].affordances and words[prep][1] != "ON" else "on"
        formula: Formula = And(tuple(Atom(pred, (o.id, dests[0].id)) for o in objs))
        fit = min(1.0, (dest_score + obj_score) / max(1.0, float(len(dest_side) + len(obj_side))))
        text = f"{pred} {', '.join(o.id for o in objs)} {dests[0].id}"
    else:  # a state change of one object: open / close / switch on / off
        verbs = classes & {"OPEN", "CLOSE", "ACTIVATE", "DEACTIVATE", "TURN"}
        if len(verbs) != 1:
            return None
        verb = verbs.pop()
        if verb == "TURN":
            verb = "ACTIVATE" if "ON" in classes else "DEACTIVATE" if "OFF" in classes else ""
        need = "openable" if verb in ("OPEN", "CLOSE") else "switchable"
        if not verb:
            return None
        targets, score = _best([e for e in ents if need in e.affordances], known)
        if len(targets) != 1 or score <= 0:
            return None
        atom = Atom("open" if need == "openable" else "turned_on", (targets[0].id,))
        formula = And((atom if verb in ("OPEN", "ACTIVATE") else Not(atom),))
        fit = min(1.0, score / max(1.0, float(len(known))))
        text = f"{verb.lower()} {targets[0].id}"
    confidence = fit * len(known) / (len(known) + unknown)
    return Match(formula, round(confidence, 3), text) if confidence >= THRESHOLD else None


def suggestions(word: str, lex: Lexicon, n: int = 3) -> list[str]:
    """The known words closest in spelling to an unknown one."""
    known = sorted({" ".join(k) for k in lex.phrases if len(k) == 1})
    return difflib.get_close_matches(word, known, n=n, cutoff=0.6)


def clarifying_error(exc: GroundingError, instruction: str, lex: Lexicon) -> GroundingError:
    """The grammar's error, with the unknown words and the closest known words named."""
    unknown = exc.unknown_words or tuple(w for w, c, _ in _words(instruction, lex) if c == "?")
    if not unknown:
        return exc
    hints = {w: tuple(suggestions(w, lex)) for w in unknown}
    parts = [
        f"{w!r}" + (f" (did you mean {' / '.join(s)}?)" if s else " (no known word is close)")
        for w, s in hints.items()
    ]
    what = "not a known verb, category, colour or name of an object in the scene"
    if exc.unknown_words:
        message = f"unknown word{'s' if len(hints) > 1 else ''} {', '.join(parts)} in {instruction!r}: {what}"
    else:
        message = f"{exc.message}; words outside the lexicon: {', '.join(parts)}"
    err = GroundingError(message, unknown_words=tuple(unknown), candidates=exc.candidates, phrase=exc.phrase)
    err.suggestions = hints
    return err
