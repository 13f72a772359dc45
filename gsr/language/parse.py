"""Instruction text -> word-class tokens (lexer) -> parse tree (lark Earley over instruction.lark)."""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedEOF, UnexpectedInput, UnexpectedToken
from lark.lexer import Lexer

from gsr.language.errors import GroundingError
from gsr.language.lexicon import FILLER, Lexicon

_PUNCT = re.compile(r"[—–;:]")
_SENTENCE_END = re.compile(r"[!?]+")
_SPLIT = re.compile(r"\s+|(?=[,.])|(?<=[,.])")
#: Classes after which "switch" is a verb ("switch on the lamp"), elsewhere the noun ("press the switch").
_CLAUSE_START = {None, "AND", "THEN", "COMMA", "ALSO", "PERIOD", "OPENER", "FIRST"}
#: Contractions written out before splitting ("don't forget to" -> "do not forget to").
CONTRACTIONS = (
    (re.compile(r"\bcan't\b"), "can not"),
    (re.compile(r"\bwon't\b"), "will not"),
    (re.compile(r"\blet's\b"), "let us"),
    (re.compile(r"n't\b"), " not"),
    (re.compile(r"'d\b"), " would"),
    (re.compile(r"'ll\b"), " will"),
    (re.compile(r"'re\b"), " are"),
    (re.compile(r"\bi'm\b"), "i am"),
    (re.compile(r"\b(that|which|what|it|there|here|who)'s\b"), r"\1 is"),
)
#: Ordinals that, at the start of a clause, order the clauses ("First, open the drawer") rather than objects.
_SEQUENCE_ORDINALS = frozenset({"first"})
#: Classes after which "open" is the adjective (the state), not the verb.
_ADJECTIVE_CONTEXT = {
    "DET",
    "POSS",
    "ALL",
    "EACH",
    "BOTH",
    "COLOR",
    "POS",
    "SIDE",
    "NAME",
    "BE",
    "IN",
    "ON",
    "TO",
    "FROM",
    "OF",
    "INSIDE",
    "AT",
    "NEAR",
    "BETWEEN",
    "WITH",
}


@dataclass(frozen=True, slots=True)
class Tok:
    """One lexical unit: its class, its value (category, colour, node id, word) and its words."""

    cls: str
    value: str
    text: str
    plural: bool = False


def _entity_for(raw: str, lex: Lexicon) -> str | None:
    """A node id written in the instruction (``blue_box``, ``drawer_middle``, ``red_cube1``), or None."""
    if raw in lex.entities:
        return raw
    tails = [i for i in lex.entities if i.rsplit("/", 1)[-1] == raw]
    return tails[0] if len(tails) == 1 else None


def _singular(word: str) -> list[str]:
    out = []
    if word.endswith("ies"):
        out.append(word[:-3] + "y")
    if word.endswith("es"):
        out.append(word[:-2])
    if word.endswith("s"):
        out.append(word[:-1])
    return out


def tokenize(text: str, lex: Lexicon) -> list[Tok]:
    """Word-class tokens of an instruction; GroundingError naming every unknown word."""
    clean = text.strip().lower().replace("\u2019", "'")
    for pattern, full in CONTRACTIONS:
        clean = pattern.sub(full, clean)
    clean = _SENTENCE_END.sub(" . ", _PUNCT.sub(" , ", clean)).replace("'s ", " ")
    raws = [r for r in _SPLIT.split(clean) if r and r.strip()]
    words: list[tuple[str, str | None]] = []  # (word, entity id if the raw token named a node)
    for raw in raws:
        raw = raw.strip().strip("\"'()")
        if not raw:
            continue
        if raw in (",", "."):
            words.append((raw, None))
            continue
        if raw.isdigit():  # "put 2 cubes in the box": a numeral
            words.append((raw, None))
            continue
        if "_" in raw or "/" in raw or any(ch.isdigit() for ch in raw):
            ent = _entity_for(raw, lex)
            if ent is not None:
                words.append((raw, ent))
                continue
            words.extend((w, None) for w in re.split(r"[_/\-]+", raw) if w)
            continue
        if (raw,) in lex.phrases:
            words.append((raw, None))
        else:
            words.extend((w, None) for w in raw.split("-") if w)
    toks: list[Tok] = []
    unknown: list[str] = []
    i = 0
    while i < len(words):
        word, ent = words[i]
        if ent is None and word.isdigit():
            toks.append(Tok("NUM", word, word))
            i += 1
            continue
        if ent is not None:
            plural = False
            toks.append(Tok("ENTITY", ent, word, plural))
            i += 1
            continue
        matched = False
        for n in range(min(lex.max_phrase, len(words) - i), 0, -1):
            if n == 1 and word in FILLER:  # politeness and adverbs, unless part of a phrase ("could you")
                matched = True
                i += 1
                break
            span = tuple(w for w, _ in words[i : i + n])
            if any(e is not None for _, e in words[i : i + n]):
                continue
            hit = lex.lookup(span)
            if hit is not None:
                cls, value = hit
                prev = toks[-1].cls if toks else None
                if span == ("switch",) and prev not in _CLAUSE_START:
                    cls, value = "NOUN", "switch"
                if cls == "OPEN" and prev in _ADJECTIVE_CONTEXT:  # "the open drawer", "that is open"
                    cls = "OPENED"
                if span[0] in _SEQUENCE_ORDINALS and n == 1 and prev in _CLAUSE_START:
                    cls = "FIRST"
                plural = value.endswith("#pl")
                if cls != "DROP":  # pacing and continuation tails ("one by one") say nothing about the goal
                    toks.append(Tok(cls, value.removesuffix("#pl"), " ".join(span), plural))
                i += n
                matched = True
                break
        if matched:
            continue
        for sing in _singular(word):
            hit = lex.lookup((sing,))
            if hit is not None and hit[0] in ("NOUN", "NAME"):
                toks.append(Tok(hit[0], hit[1].removesuffix("#pl"), word, True))
                matched = True
                break
        if not matched:
            unknown.append(word)
        i += 1
    _mark_back(toks)
    if unknown:
        names = ", ".join(repr(w) for w in dict.fromkeys(unknown))
        raise GroundingError(
            f"unknown word{'s' if len(set(unknown)) > 1 else ''} {names} in {text!r}: not a known verb, "
            "category, colour or name of an object in the scene",
            unknown_words=tuple(dict.fromkeys(unknown)),
        )
    if not toks:
        raise GroundingError(f"empty instruction {text!r}")
    return toks


def _mark_back(toks: list[Tok]) -> None:
    """``put the cup back in the box``: ``back`` before a preposition, after an object, is a particle."""
    for i in range(1, len(toks) - 1):
        t = toks[i]
        if (
            t.text == "back"
            and toks[i + 1].cls in ("IN", "ON", "TO", "INSIDE")
            and toks[i - 1].cls in ("NOUN", "COLORNOUN", "NAME", "ENTITY", "IT", "THEM", "PLACE")
        ):
            toks[i] = Tok("BACK", "back", "back")


@lru_cache(maxsize=1)
def _parser() -> Lark:
    grammar = resources.files("gsr.language").joinpath("instruction.lark").read_text(encoding="utf-8")
    return Lark(grammar, parser="earley", lexer=_ClassLexer, ambiguity="explicit", start="start")


class _ClassLexer(Lexer):
    """A lark lexer over pre-classified tokens: the parse input is the list of Tok."""

    def __init__(self, lexer_conf) -> None:
        pass

    def lex(self, lexer_state, parser_state=None):
        items = lexer_state if isinstance(lexer_state, list) else lexer_state.text
        for i, tok in enumerate(items):
            yield Token(tok.cls, tok, start_pos=i, line=1, column=i + 1)


def _describe_token(tokens: list[Tok], pos: int | None) -> str:
    if pos is None or pos >= len(tokens):
        return "the end of the instruction"
    return repr(tokens[pos].text)


def parse_tokens(tokens: list[Tok], text: str) -> Tree:
    """The parse tree (ambiguities kept as ``_ambig`` nodes); GroundingError naming where parsing failed."""
    try:
        return _parser().parse(tokens)  # type: ignore[arg-type]
    except UnexpectedToken as exc:
        tok = exc.token.value if isinstance(exc.token.value, Tok) else None
        where = repr(tok.text) if tok else "the end of the instruction"
        raise GroundingError(
            f"cannot understand {text!r} at {where}", phrase=tok.text if tok else None
        ) from None
    except UnexpectedEOF:
        raise GroundingError(f"cannot understand {text!r}: the instruction ends too early") from None
    except UnexpectedInput as exc:
        pos = getattr(exc, "pos_in_stream", None)
        raise GroundingError(
            f"cannot understand {text!r} at {_describe_token(tokens, pos)}",
        ) from None
