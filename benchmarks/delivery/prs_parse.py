"""Parsing PRS's free-form delivery requests with general constructions.

A request is two sentences (the person's own request, then a third party's with the person described).
From each sentence: the object phrase (the noun phrase after a fetch verb, up to its preposition), the
source (``from/on/off`` + receptacle and room words, or an earlier ``go to the <room>``), and the
destination (rooms after the object phrase, ``for me`` / ``my bedroom`` meaning the requester's own
places). Object words are matched against the detector's type labels through a small lexicon of
synonyms; room words against the station's room names (numbers dropped, ``bedroom`` = ``bed room``).
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass, field

from gsr.building.prs import Station

FETCH_VERBS = (
    "pick up|picking up|fetch|fetching|grab|grabbing|grasp|grasping|retrieve|retrieving|collect|collecting|"
    "get|take|taking|bring|bringing|carry|carrying|transport|transporting|deliver|delivering|move|hand|"
    "need|want|like"
)
#: What ends an object phrase: a preposition, a comma, or "and" + a verb ("red and white cake" goes on).
PHRASE_END = (
    r"(?:\s*[,;.]|\s+(?:from|on|off|in|inside|at|that|which|to|then|near|beside|located|sitting|placed|lying"
    rf"|and\s+(?:then\s+)?(?:{FETCH_VERBS}|give|go|head|place|put|drop|leave))\b)"
)
STOP = frozenset(
    [
        "the",
        "a",
        "an",
        "of",
        "with",
        "and",
        "its",
        "it",
        "is",
        "that",
        "this",
        "some",
        "one",
        "in",
        "on",
        "to",
        "for",
        "from",
        "at",
        "by",
    ]
)
#: Request words -> the words detector labels use (a lexicon of object names, not of sentences).
SYNONYMS: dict[str, tuple[str, ...]] = {
    "phone": ("phone",),
    "cellphone": ("mobile", "phone"),
    "smartphone": ("mobile", "phone"),
    "mobile": ("mobile",),
    "gamepad": ("consolegaming", "pad"),
    "controller": ("consolegaming", "pad"),
    "console": ("consolegaming",),
    "gaming": ("consolegaming",),
    "joystick": ("consolegaming", "pad"),
    "medicine": ("medication",),
    "medicinal": ("medication",),
    "vial": ("medication", "bottle"),
    "injection": ("injectable",),
    "chili": ("chill", "chili"),
    "chilli": ("chill", "chili"),
    "pepper": ("chill",),
    "beans": ("beans",),
    "bean": ("beans",),
    "peas": ("pea",),
    "tin": ("can",),
    "mug": ("cup",),
    "cake": ("cake",),
    "lid": ("lid",),
    "cap": ("lid",),
}


def words(text: str) -> list[str]:
    """Lower-case word tokens (hyphens split words)."""
    return re.findall(r"[a-z0-9]+", text.lower().replace("-", " "))


def label_words(label: str) -> list[str]:
    """A detector label's words: ``PlasticBottleWithGreenLid`` -> plastic bottle green lid."""
    parts = re.sub(r"(?<=[a-z])(?=[A-Z0-9])|_", " ", label).lower().split()
    return [p for p in parts if p not in STOP and not p.isdigit()]


def expand(tokens: list[str]) -> set[str]:
    """Tokens plus the label words their synonyms stand for (plural s dropped too)."""
    out: set[str] = set()
    for t in tokens:
        out.add(t)
        out.update(SYNONYMS.get(t, ()))
        if t.endswith("s") and len(t) > 3:
            out.add(t[:-1])
            out.update(SYNONYMS.get(t[:-1], ()))
    return out


def label_score(label: str, phrase_tokens: list[str]) -> float:
    """How well a detector label matches an object phrase: the fraction of the label's words the phrase
    has, with a small bonus per matched word (so the more specific label wins), 0 if its head noun
    (the label's last non-colour word) is missing."""
    lw = label_words(label)
    if not lw:
        return 0.0
    have = expand(phrase_tokens)
    matched = [w for w in lw if w in have]
    if not matched:
        return 0.0
    pairs = set(itertools.pairwise(phrase_tokens))
    bound = sum((a, b) in pairs for a, b in itertools.pairwise(lw))  # "green lid" stays together
    return len(matched) / len(lw) + 0.05 * len(matched) + 0.1 * bound


@dataclass
class RoomMatcher:
    """Room mentions -> room ids, from the station's room names (numbers dropped)."""

    station: Station
    heads: list[tuple[tuple[str, ...], list[str]]] = field(default_factory=list)

    def __post_init__(self) -> None:
        by_head: dict[tuple[str, ...], list[str]] = {}
        for r in self.station.rooms:
            toks = [t for t in normalise(r.name).split() if not t.isdigit() and t != "room"]
            if toks:
                by_head.setdefault(tuple(toks), []).append(r.id)
        # longest heads first so 'office space' wins over 'office'
        self.heads = sorted(by_head.items(), key=lambda kv: -len(kv[0]))

    def mentions(self, text: str) -> list[tuple[int, tuple[str, ...], list[str]]]:
        """``(position, head, room ids)`` for each room mention, in text order. A mention must end its
        clause or be followed by ``room``/``area``/``space``, a possessive or a function word: *the kitchen
        counter* and *a white lab coat* name furniture and clothes, not rooms."""
        found = []
        for c, chunk in enumerate(re.split(r"[,;.!?:]", text)):
            toks = normalise(chunk).split()
            taken: set[int] = set()
            for head, ids in self.heads:
                n = len(head)
                for k in range(len(toks) - n + 1):
                    if tuple(toks[k : k + n]) != head or taken & set(range(k, k + n)):
                        continue
                    nxt = toks[k + n] if k + n < len(toks) else None
                    if nxt is not None and nxt not in ROOM_FOLLOWERS:
                        continue
                    taken.update(range(k, k + n))
                    found.append((1000 * c + k, head, ids))
        return sorted(found)


#: Words that may follow a room mention.
ROOM_FOLLOWERS = frozenset(
    [
        "room",
        "rooms",
        "area",
        "space",
        "s",
        "and",
        "then",
        "to",
        "for",
        "with",
        "on",
        "in",
        "at",
        "from",
        "of",
        "where",
        "who",
        "which",
        "that",
        "she",
        "he",
        "they",
        "it",
        "please",
        "so",
        "while",
        "or",
        "but",
        "i",
        "me",
        "my",
        "him",
        "her",
        "them",
        "by",
        "near",
        "next",
        "before",
        "after",
        "there",
        "here",
    ]
)


def normalise(text: str) -> str:
    """Lower case, punctuation to spaces, ``bedroom`` -> ``bed room``, ``officespace`` -> ``office space``,
    ``hallway`` -> ``hall``, ``dining`` kept."""
    t = " " + re.sub(r"[^a-z0-9']+", " ", text.lower()) + " "
    for a, b in (
        (" bedroom", " bed room"),
        (" bedrooms", " bed rooms"),
        ("officespace", "office space"),
        (" hallway", " hall"),
        (" living area", " living room"),
        (" meeting room", " conference room"),
        (" shared office", " office space"),
        ("'s ", " s "),
    ):
        t = t.replace(a, b)
    return " ".join(t.split())


@dataclass
class ParsedRequest:
    """What the agent takes from a request."""

    object_tokens: list[str]
    source_tokens: list[str]
    source_rooms: list[str]
    dest_rooms: list[str]
    dest_heads: list[tuple[str, ...]]
    own_place: str | None  # 'bed' / 'office' when the request says my/her/his bedroom/office
    sentences: list[str]


class RequestParseError(ValueError):
    """The request has no recognisable object phrase."""


def split_sentences(instruction: str) -> list[str]:
    """Sentences of an instruction (PRS joins its two without a space: ``...for me.Fetch the ...``)."""
    parts = re.split(r"(?<=[.!?])\s*(?=[A-Z])", instruction.strip())
    return [p.strip() for p in parts if p.strip()]


_OBJ = re.compile(
    rf"\b(?:{FETCH_VERBS})\s+(?:me\s+)?(?:the|a|an|that|this|some)\s+(?P<obj>.+?)(?={PHRASE_END})", re.I
)
_SRC = re.compile(
    r"(?:(?:that|which)\s+(?:is|are|was|sits|lies|stands)\s+|(?:sitting|lying|placed|located|resting|kept)\s+)?"
    r"\b(?:from|on|off|in|at)\s+(?P<src>.+?)(?=\s+(?:and|then|to|for|over|back|brought|delivered)\b|[,;.?!]|$)",
    re.I,
)


def parse_request(instruction: str, rooms: RoomMatcher, labels: list[str]) -> ParsedRequest:
    """Object phrase, source and destination of a request; ``RequestParseError`` when no sentence has an
    object phrase naming any detector label."""
    sentences = split_sentences(instruction)
    obj_tokens: list[str] = []
    src_tokens: list[str] = []
    src_rooms: list[str] = []
    dest_rooms: list[str] = []
    dest_heads: list[tuple[str, ...]] = []
    own = None
    for s in sentences:
        best = None
        for m in _OBJ.finditer(s):
            toks = [t for t in words(m.group("obj")) if t not in STOP]
            score = max((label_score(lab, toks) for lab in labels), default=0.0)
            if score > 0 and (best is None or score > best[0]):
                best = (score, m, toks)
        if best is None:
            continue
        _, m, toks = best
        obj_tokens += toks
        rest = s[m.end("obj") :]
        src = _SRC.match(rest.strip())
        src_text = src.group("src") if src else ""
        after = rest.strip()[src.end() :] if src else rest
        before = s[: m.start()]
        for _, _, ids in rooms.mentions(before + " " + src_text):
            src_rooms += [i for i in ids if i not in src_rooms]
        src_tokens += words(src_text)
        low = normalise(after)
        if re.search(r"\b(?:my|her|his|their)\s+bed\s+room", low):
            own = "bed"
        elif re.search(r"\b(?:my|her|his|their)\s+office\b", low) or re.search(r"\b[a-z]+ s office\b", low):
            own = own or "office"
        for _, head, ids in rooms.mentions(after):
            dest_heads.append(head)
            dest_rooms += [i for i in ids if i not in dest_rooms]
    if not obj_tokens:
        raise RequestParseError("no object phrase naming a known object type")
    return ParsedRequest(obj_tokens, src_tokens, src_rooms, dest_rooms, dest_heads, own, sentences)
