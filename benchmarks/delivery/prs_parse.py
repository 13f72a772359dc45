"""Parsing PRS's free-form delivery requests on the project's language stack.

Words are classified by the grounder's own lexicon (``gsr.language.lexicon.build_lexicon``: its function
words and word classes, everyday verbs, colours, registered nouns, fillers) plus the sections of the
everyday vocabulary (``data/language/vocabulary.yaml``) written for free-form requests: spellings and
compounds, place-name phrases, object-name synonyms, colour shades, materials, search verbs, irregular
participles, pronouns (``me`` = the requester), connectives, place nouns, particles and appearance
words. Nothing here is keyed to a sentence, a task, a person or an object of PRS's data: the
constructions are general ones.

From each sentence of a request:

- the **object phrase**: the noun phrase after a fetch, give or search verb (class ``PICK``, ``GET``,
  ``PLACE``, ``GIVE``, ``WANT`` or a search verb), from its determiner up to a preposition, a relative
  clause, a participle, punctuation, ``then`` or ``and`` + anything but a colour or material (so *red
  and white bagged cake* stays whole); among several, the one naming a detector label best. Its
  structure: head words (those of the best label), colours (shades mapped to base colours), the lid or
  cap colour, materials and the remaining attributes;
- the **source**: ``from/on/off/in/at`` + a receptacle and room phrase after the object (also after
  ``that is`` / ``sitting``), and rooms named before the verb (*go to the kitchen and ...*);
- the **destination**: rooms named after the source; *my/her bedroom*, *Ethan's office* mean the
  recipient's own place;
- the **recipient**: names (capitalised words the lexicon does not know), whether the requester is the
  recipient (*bring it to me*, *for me*), and appearance words (after *wearing*, *in*, *with* ...).

Object words are matched against the detector's camel-case type labels by their words, through the
vocabulary's spellings, synonyms and shades; room words against the station's room names (numbers
dropped, spellings and place phrases applied). A request with no object phrase naming any label raises
``RequestParseError`` with the reason; the caller fails that task and goes on.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass, field
from functools import lru_cache

from gsr.benchmarks.delivery.building.prs_station import Station

from gsr.categories import COLOR_SYNONYMS, COLORS, MATERIALS
from gsr.language.lexicon import FILLER, Lexicon, build_lexicon, vocabulary
from gsr.language.parse import CONTRACTIONS
from gsr.scene_graph import SceneGraph

#: Word classes of the grounder that take an object to fetch or give (plus the vocabulary's search verbs).
FETCH_CLASSES = frozenset({"PICK", "GET", "PLACE", "GIVE", "WANT", "FIND"})
#: Classes that end an object phrase.
NP_END = frozenset(
    {"FROM", "ON", "OFF", "IN", "INSIDE", "AT", "NEAR", "TO", "THAT", "PLACED", "THEN", "PUNCT", "FOR", "BE",
     "BEHIND", "UNDER", "BETWEEN", "PARTICIPLE", "AFTER", "BEFORE", "CONNECTIVE", "ALSO", "ENDUP", "PARTICLE"}
)  # fmt: skip
#: Prepositions that open a source phrase after the object.
SOURCE_PREPS = frozenset({"FROM", "ON", "OFF", "IN", "INSIDE", "AT"})
#: Classes that end a source phrase.
SOURCE_END = frozenset({"AND", "THEN", "TO", "PUNCT", "FOR", "PARTICIPLE", "PARTICLE", "CONNECTIVE"})
#: Determiner-like classes that open an object phrase.
DETERMINERS = frozenset({"DET", "POSS", "THIS", "THAT", "ME", "PRON_POSS"})
#: Classes that may open a noun phrase without a determiner (*fetch red apples*, *grab two cups*).
BARE_NP = frozenset({"COLOR", "COLORNOUN", "NOUN", "NAME", "WORD", "SIZE", "NUM", "POS", "SIDE"})
#: Content classes: a room word followed by one of these is a modifier (*kitchen counter*), not a room.
CONTENT = frozenset({"NOUN", "COLORNOUN", "NAME", "WORD"})
#: Function classes whose words are no attribute of an object (the grounder's closed classes).
STOP_CLASSES = frozenset(
    {"DET", "OF", "WITH", "AND", "IT", "BE", "THAT", "THIS", "ONE", "IN", "ON", "TO", "FOR", "FROM", "AT",
     "BY", "POSS", "INSIDE", "THEM"}
)  # fmt: skip


@dataclass(frozen=True, slots=True)
class Word:
    """One word (or lexicon phrase) of a request: its text, class and whether it is a proper name."""

    text: str
    cls: str
    proper: bool = False


@lru_cache(maxsize=1)
def lexicon() -> Lexicon:
    """The grounder's lexicon without a scene: function words, everyday verbs, colours, registered nouns."""
    return build_lexicon(SceneGraph())


@lru_cache(maxsize=1)
def _extra_phrases() -> dict[tuple[str, ...], str]:
    """Word sequences -> classes from the free-form sections of the vocabulary."""
    v = vocabulary()
    out: dict[tuple[str, ...], str] = {}
    for w in v["search_verbs"]:
        out[tuple(w.split())] = "FIND"
    for w in v["participles"]:
        out[(w,)] = "PARTICIPLE"
    for w in v["pronouns"].get("requester", ()):
        out[(w,)] = "ME"
    for w in v["pronouns"].get("other", ()):
        out[(w,)] = "PRON_POSS" if w in ("her", "his", "their") else "PRON"
    for w in v["connectives"]:
        out[(w,)] = "CONNECTIVE"
    for w in v["particles"]:
        out[(w,)] = "PARTICLE"
    return out


@lru_cache(maxsize=1)
def stop_words() -> frozenset[str]:
    """Function words that are no attribute of an object: the grounder's closed classes above."""
    lex = lexicon()
    return frozenset(k[0] for k, (cls, _) in lex.phrases.items() if len(k) == 1 and cls in STOP_CLASSES)


STOP = stop_words()


def spell(tokens: list[str]) -> list[str]:
    """Tokens with the vocabulary's spellings and compounds applied (``bedroom`` -> bed room)."""
    sp = vocabulary()["spellings"]
    out: list[str] = []
    for t in tokens:
        out.extend(sp[t].split() if t in sp else (t,))
    return out


@lru_cache(maxsize=1)
def _phrase_table() -> tuple[tuple[tuple[str, ...], list[str]], ...]:
    """The vocabulary's place phrases as (words, replacement words), longest first."""
    return tuple(
        sorted(
            ((tuple(k.split()), v.split()) for k, v in vocabulary()["phrases"].items()),
            key=lambda kv: -len(kv[0]),
        )
    )


def place_phrases(tokens: list[str]) -> list[str]:
    """Tokens with the vocabulary's place phrases replaced (``meeting room`` -> conference room)."""
    return [t for t, _ in _place_words([(t, "") for t in tokens])]


def _place_words(flat: list[tuple[str, str]]) -> list[tuple[str, str]]:
    """``place_phrases`` over (word, class) pairs; a replaced phrase's words take the class of its last."""
    out: list[tuple[str, str]] = []
    i = 0
    while i < len(flat):
        for k, v in _phrase_table():
            if tuple(t for t, _ in flat[i : i + len(k)]) == k:
                cls = flat[i + len(k) - 1][1]
                out.extend((t, cls) for t in v)
                i += len(k)
                break
        else:
            out.append(flat[i])
            i += 1
    return out


def words(text: str) -> list[str]:
    """Lower-case word tokens (hyphens split words; ``'s`` becomes the word ``s``), spellings applied."""
    t = text.lower().replace("\u2019", "'").replace("-", " ").replace("'s ", " s ")
    return spell(re.findall(r"[a-z0-9]+", t))


def normalise(text: str) -> str:
    """Lower-case words with spellings and place phrases applied (``bedroom`` -> ``bed room``,
    ``officespace`` -> ``office space``, ``meeting room`` -> ``conference room``)."""
    return " ".join(place_phrases(words(text + " ")))


def label_words(label: str) -> list[str]:
    """A detector label's words: ``PlasticBottleWithGreenLid`` -> plastic bottle green lid."""
    parts = re.sub(r"(?<=[a-z])(?=[A-Z0-9])|_", " ", label).lower().split()
    return [p for p in spell(parts) if p not in STOP and not p.isdigit()]


def singular(word: str) -> str | None:
    """The singular of a regular plural (``beans`` -> bean, ``boxes`` -> box), or None."""
    if len(word) > 4 and word.endswith("ies"):
        return word[:-3] + "y"
    if len(word) > 4 and word.endswith(("ches", "shes", "xes", "sses")):
        return word[:-2]
    if len(word) > 3 and word.endswith("s") and not word.endswith("ss"):
        return word[:-1]
    return None


def base_color(word: str) -> str | None:
    """The base colour a colour word or shade is seen as (``navy`` -> blue, ``yellowish`` -> yellow)."""
    shades = vocabulary()["shades"]
    w = COLOR_SYNONYMS.get(word, word)
    if w in COLORS:
        return w
    if word in shades:
        return shades[word]
    if word.endswith("ish") and len(word) > 5:  # reddish, bluish, yellowish, greenish
        stem = word[:-3]
        for cand in (stem, stem[:-1], stem + "e"):
            c = base_color(cand) if cand != word else None
            if c:
                return c
    return None


def material_of(word: str) -> str | None:
    """The material a word says (``wooden`` -> wood, ``marble`` -> stone), or None."""
    for material, ws in vocabulary()["materials"].items():
        if word in ws:
            return material
    return word if word in MATERIALS else None


def expand(tokens: list[str]) -> set[str]:
    """Tokens plus singular forms, the label words their synonyms stand for, and base colours."""
    syn = vocabulary()["synonyms"]
    out: set[str] = set()
    for t in tokens:
        one = singular(t)
        for f in (t, one) if one else (t,):
            out.add(f)
            out.update(syn.get(f, ()))
            c = base_color(f)
            if c:
                out.add(c)
    return out


def label_score(label: str, phrase_tokens: list[str]) -> float:
    """How well a detector label matches an object phrase: the fraction of the label's words the phrase
    has, with a small bonus per matched word (so the more specific label wins) and per adjacent pair the
    phrase keeps together (*green lid*); 0 when no word matches."""
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


def classify(sentence: str) -> list[Word]:
    """The words of a sentence with their classes: the grounder's lexicon (longest phrase first), the
    vocabulary's free-form sections, punctuation (``PUNCT``), possessive ``'s`` (``POSS_S``), fillers
    (``FILLER``); unknown words are ``WORD``, and ``proper`` when capitalised inside the sentence."""
    text = sentence.replace("\u2019", "'")
    raw = re.findall(r"[A-Za-z0-9]+(?:'[A-Za-z]+)?|[,.;:!?]", text.replace("-", " "))
    toks: list[tuple[str, bool]] = []  # (lower-case word, capitalised mid-sentence)
    for k, r in enumerate(raw):
        low = r.lower()
        for pattern, full in CONTRACTIONS:
            low = pattern.sub(full, low)
        low = low.replace("'s", " s").replace("'", " ")
        parts = low.split()
        cap = r[:1].isupper() and k > 0 and raw[k - 1] not in ".!?"
        for n, p in enumerate(spell(parts)):
            toks.append((p, cap and n == 0))
    lex, extra = lexicon(), _extra_phrases()
    out: list[Word] = []
    i = 0
    while i < len(toks):
        w, cap = toks[i]
        if w in ",.;:!?":
            out.append(Word(w, "PUNCT"))
            i += 1
            continue
        if w == "s" and out and out[-1].cls != "PUNCT":
            out.append(Word(w, "POSS_S"))
            i += 1
            continue
        hit = None
        for n in range(min(lex.max_phrase, len(toks) - i), 0, -1):
            span = tuple(t for t, _ in toks[i : i + n])
            if any(t in ",.;:!?" for t in span):
                continue
            if span in extra:
                hit = (n, extra[span])
                break
            found = lex.lookup(span)
            if found is not None and found[0] != "DROP":  # "for me" says who: kept as words
                hit = (n, found[0])
                break
        if hit is None and singular(w):
            found = lex.lookup((singular(w),))
            if found is not None and found[0] in ("NOUN", "NAME"):
                hit = (1, found[0])
        if hit is not None and hit[0] == 1 and w in FILLER and hit[1] != "NOUN":
            hit = (1, "FILLER")
        if hit is None:
            cls = "FILLER" if w in FILLER else "WORD"
            out.append(Word(w, cls, proper=cap and cls == "WORD"))
            i += 1
            continue
        n, cls = hit
        out.append(Word(" ".join(t for t, _ in toks[i : i + n]), cls))
        i += n
    return out


def _texts(ws: list[Word]) -> list[str]:
    return [t for w in ws for t in w.text.split()]


@dataclass
class RoomMatcher:
    """Room mentions -> room ids, from the station's room names (numbers and the station's generic place
    noun dropped: *lab room 2* is the *lab*; *office space* keeps *space*)."""

    station: Station
    heads: list[tuple[tuple[str, ...], list[str]]] = field(default_factory=list)

    def __post_init__(self) -> None:
        by_head: dict[tuple[str, ...], list[str]] = {}
        # the station's generic place noun ("room" of "lab room 2"): a place noun in half its room names
        names = [set(normalise(r.name).split()) for r in self.station.rooms]
        nouns = {w for w in vocabulary()["place_nouns"] if 2 * sum(w in n for n in names) >= len(names)}
        for r in self.station.rooms:
            toks = [t for t in normalise(r.name).split() if not t.isdigit() and t not in nouns]
            if toks:
                by_head.setdefault(tuple(toks), []).append(r.id)
        # longest heads first so 'office space' wins over 'office'
        self.heads = sorted(by_head.items(), key=lambda kv: -len(kv[0]))

    def ids_of(self, head: tuple[str, ...]) -> list[str]:
        """The rooms a head names."""
        return next((ids for h, ids in self.heads if h == head), [])

    def mentions(self, text: str | list[Word]) -> list[tuple[int, tuple[str, ...], list[str]]]:
        """``(position, head, room ids)`` for each room mention, in text order. A mention must end its
        clause or be followed by a place noun (*room*, *area*), a possessive or a function word: *the
        kitchen counter* and *a white lab coat* name furniture and clothes, not rooms."""
        ws = classify(text) if isinstance(text, str) else text
        # one entry per word (a lexicon phrase is split back into its words, keeping its class), with the
        # vocabulary's place phrases applied across words ("shared office" -> office space)
        flat = _place_words([(t, w.cls) for w in ws for t in w.text.split()])
        place = set(vocabulary()["place_nouns"])
        found = []
        taken: set[int] = set()
        for head, ids in self.heads:
            n = len(head)
            for k in range(len(flat) - n + 1):
                if tuple(t for t, _ in flat[k : k + n]) != head or taken & set(range(k, k + n)):
                    continue
                nxt = flat[k + n] if k + n < len(flat) else None
                if nxt is not None and nxt[1] in CONTENT and nxt[0] not in place:
                    continue
                taken.update(range(k, k + n))
                found.append((k, head, ids))
        return sorted(found)


@dataclass
class ObjectPhrase:
    """The object a sentence asks for: its words and their roles."""

    text: str
    tokens: list[str]  # content words, in order
    head: list[str]  # the words of the best-matching detector label
    colors: list[str]  # base colours of the object (shades mapped)
    lid_color: str | None  # the colour of its lid or cap (*a white bottle with a green lid*)
    materials: list[str]
    attributes: list[str]  # the other words (*sleek*, *stickered*, *round*)


@dataclass
class Recipient:
    """Who the object goes to, as the request says it."""

    names: list[str] = field(default_factory=list)
    requester: bool = False  # "bring it to me", "for me": the person who asks
    appearance: list[str] = field(default_factory=list)


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
    objects: list[ObjectPhrase] = field(default_factory=list)
    recipient: Recipient = field(default_factory=Recipient)


class RequestParseError(ValueError):
    """The request has no recognisable object phrase."""


def split_sentences(instruction: str) -> list[str]:
    """Sentences of an instruction (PRS joins its two without a space: ``...for me.Fetch the ...``)."""
    parts = re.split(r"(?<=[.!?])\s*(?=[A-Z])", instruction.strip())
    return [p.strip() for p in parts if p.strip()]


def _is_modifier(w: Word) -> bool:
    """A colour, shade, size or material word: ``and`` before it continues a noun phrase."""
    return w.cls in ("COLOR", "SIZE") or base_color(w.text) is not None or material_of(w.text) is not None


def object_phrases(ws: list[Word]) -> list[tuple[int, int, int]]:
    """``(verb, start, end)`` word spans of the noun phrases after fetch/give/search verbs."""
    out = []
    for v, w in enumerate(ws):
        if w.cls not in FETCH_CLASSES:
            continue
        k = v + 1
        while k < len(ws):  # "pick up the", "bring me the", "give Ada the", "deliver to her the"
            c = ws[k].cls
            if (
                c == "TO"
                and k + 1 < len(ws)
                and (ws[k + 1].cls in ("ME", "PRON", "PRON_POSS") or ws[k + 1].proper)
            ):
                k += 1
                continue
            if c not in ("UP", "OUT", "ME", "PRON", "PRON_POSS", "FILLER", "PARTICLE") and not ws[k].proper:
                break
            if c in ("ME", "PRON", "PRON_POSS") and k + 1 < len(ws) and ws[k + 1].cls not in DETERMINERS:
                break
            k += 1
        if k >= len(ws):
            continue
        if ws[k].cls in DETERMINERS:
            start = k + 1
        elif ws[k].cls in BARE_NP and not ws[k].proper:  # no determiner: "fetch red apples", "grab two cups"
            start = k
        else:
            continue
        end = start
        while end < len(ws):
            c = ws[end].cls
            if c == "AND":
                if end + 1 < len(ws) and _is_modifier(ws[end + 1]):
                    end += 1
                    continue
                break
            if c in NP_END or (c in FETCH_CLASSES and end > start):
                break
            end += 1
        if end > start:
            out.append((v, start, end))
    return out


def describe_object(ws: list[Word], labels: list[str]) -> tuple[float, ObjectPhrase]:
    """The best label score of an object phrase and its structure."""
    toks = [t for t in _texts(ws) if t not in STOP]
    scores = {lab: label_score(lab, toks) for lab in labels}
    best = max(scores, key=lambda lab: scores[lab], default=None)
    score = scores[best] if best else 0.0
    head = label_words(best) if best and score > 0 else []
    have_head = expand(head)
    colors, materials, attrs = [], [], []
    lid = None
    for k, t in enumerate(toks):
        c, m = base_color(t), material_of(t)
        nxt = toks[k + 1] if k + 1 < len(toks) else None
        if c and nxt is not None and "lid" in expand([nxt]):
            lid = c
        elif c:
            colors.append(c)
        elif m:
            materials.append(m)
        elif t not in have_head and not expand([t]) & set(head):
            attrs.append(t)
    text = " ".join(w.text for w in ws)
    return score, ObjectPhrase(text, toks, head, colors, lid, materials, attrs)


def _appearance(ws: list[Word], skip: set[str]) -> list[str]:
    """Content words after an appearance opener (*wearing a white lab coat*, *in the black jacket*)."""
    out: list[str] = []
    on = False
    openers = set(vocabulary()["appearance"])
    for w in ws:
        if w.text in openers:
            on = True
            continue
        if w.cls in ("PUNCT", "CONNECTIVE", "TO", "FROM") or w.cls in FETCH_CLASSES:
            on = False
            continue
        if on and w.cls not in STOP_CLASSES and w.cls not in ("ME", "PRON", "PRON_POSS", "FILLER"):
            out += [t for t in w.text.split() if t not in skip and t not in STOP]
    return list(dict.fromkeys(out))


def _own_place(ws: list[Word]) -> str | None:
    """'bed' / 'office' when words say *my/her/his bedroom*, *my office*, *Ethan's office*."""
    low = " ".join(normalise(w.text) for w in ws)
    if re.search(r"\b(?:my|her|his|their|our)\s+bed\s+room", low):
        return "bed"
    if re.search(r"\b(?:my|her|his|their|our)\s+office\b", low) or re.search(r"\b[a-z]+ s office\b", low):
        return "office"
    return None


def _merge_own(own: str | None, new: str | None) -> str | None:
    """The recipient's own place so far and a newly said one: a bedroom wins over an office."""
    return new if new == "bed" or own is None else own


def _pronoun_source(ws: list[Word]) -> tuple[int, int] | None:
    """The span of the place phrase of a statement where the object is: *it is on the desk in the office*,
    *it should be sitting on ...*, *you will find it in the kitchen* (``it``/``them`` + a form of *be* or a
    placing participle, or a search verb before ``it``; then a source preposition, up to the clause's
    end). A command (*put it in the kitchen*) is no such statement."""
    for k, w in enumerate(ws):
        if w.cls not in ("IT", "THEM"):
            continue
        j = k + 1
        while j < len(ws) and ws[j].cls in ("BE", "PLACED", "FILLER", "MODAL"):
            j += 1
        stated = j > k + 1 or (k > 0 and ws[k - 1].cls == "FIND")
        if stated and j < len(ws) and ws[j].cls in SOURCE_PREPS:
            end = j + 1
            while end < len(ws) and ws[end].cls not in SOURCE_END:
                end += 1
            return (j + 1, end)
    return None


def parse_request(instruction: str, rooms: RoomMatcher, labels: list[str]) -> ParsedRequest:
    """Object phrase, source, destination and recipient of a request; ``RequestParseError`` when no
    sentence has an object phrase naming any detector label."""
    sentences = split_sentences(instruction)
    obj_tokens: list[str] = []
    objects: list[ObjectPhrase] = []
    src_tokens: list[str] = []
    src_rooms: list[str] = []
    dest_rooms: list[str] = []
    dest_heads: list[tuple[str, ...]] = []
    own = None
    recipient = Recipient()
    room_words = {t for h, _ in rooms.heads for t in h}
    for s in sentences:
        ws = classify(s)
        best = None
        for v, a, b in object_phrases(ws):
            score, phrase = describe_object(ws[a:b], labels)
            if score > 0 and (best is None or score > best[0]):
                best = (score, v, a, b, phrase)
        names = [w.text.title() for w in ws if w.proper and w.text not in room_words]
        recipient.names += [n for n in names if n not in recipient.names]
        if best is None:  # "It is on the desk in the office." / "I'm in my bedroom."
            span = _pronoun_source(ws)
            src_words = ws[span[0] : span[1]] if span else []
            people = any(w.cls in ("ME", "PRON") or w.proper for w in ws)
            rest: list[Word] = []
            if not src_words and not people and describe_object(ws, labels)[0] > 0:
                # "The desk in the office has a blue mug on it: take it to ...": where the object is, up to
                # the first verb or "to"
                cut = next((k for k, w in enumerate(ws) if w.cls in FETCH_CLASSES or w.cls == "TO"), len(ws))
                src_words, rest = ws[:cut], ws[cut:]
            if src_words:
                for _, _, ids in rooms.mentions(src_words):
                    src_rooms += [i for i in ids if i not in src_rooms]
                src_tokens += _texts(src_words)
                for _, head, ids in rooms.mentions(rest):
                    dest_heads.append(head)
                    dest_rooms += [i for i in ids if i not in dest_rooms]
            else:
                own = _merge_own(own, _own_place(ws))
                for _, head, ids in rooms.mentions(ws):
                    dest_heads.append(head)
                    dest_rooms += [i for i in ids if i not in dest_rooms]
            continue
        _, v, a, b, phrase = best
        objects.append(phrase)
        obj_tokens += phrase.tokens
        # the source: [that is | sitting ...] from/on/in ... up to and/then/to/for or punctuation
        k = b
        while k < len(ws) and ws[k].cls in ("THAT", "BE", "PLACED"):
            k += 1
        src_end = k
        said = _pronoun_source(ws[b:])  # "I need the cup in my office; it is on the kitchen table"
        if said:
            src_words = ws[b + said[0] : b + said[1]]
            src_end = b
        elif k < len(ws) and ws[k].cls in SOURCE_PREPS:
            src_end = k + 1
            while src_end < len(ws) and ws[src_end].cls not in SOURCE_END:
                src_end += 1
            src_words = ws[k + 1 : src_end]
        else:
            src_words, src_end = [], b
        before = ws[:v]
        person_first = any(w.proper for w in before)  # "Locate Ada in the gym and give her the ..."
        for _, _, ids in rooms.mentions(([] if person_first else [*before, Word(",", "PUNCT")]) + src_words):
            src_rooms += [i for i in ids if i not in src_rooms]
        src_tokens += _texts(src_words)
        after = (before if person_first else []) + [Word(",", "PUNCT")] + ws[src_end:]
        if said:  # the statement's place is the source, not a destination
            after = (before if person_first else []) + [Word(",", "PUNCT")] + ws[b : b + said[0]]
            after += ws[b + said[1] :]
        own = _merge_own(own, _own_place(after))
        for _, head, ids in rooms.mentions(after):
            dest_heads.append(head)
            dest_rooms += [i for i in ids if i not in dest_rooms]
        # "to me", "for me", "bring me the ...": the requester receives it
        tail = ws[v + 1 : a] + after
        if any(w.cls == "ME" and w.text in ("me", "us") for w in tail):
            recipient.requester = True
        skip = room_words | set(vocabulary()["place_nouns"])
        recipient.appearance += [t for t in _appearance(after, skip) if t not in recipient.appearance]
    if not obj_tokens:
        raise RequestParseError("no object phrase naming a known object type")
    return ParsedRequest(
        obj_tokens, src_tokens, src_rooms, dest_rooms, dest_heads, own, sentences, objects, recipient
    )
