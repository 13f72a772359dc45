"""Parse tree -> intents: what each clause asks for, with its noun phrases resolved against the graph.

Each clause becomes an :class:`Intent` (place, pick, open, close, turn_on, turn_off, press, tower).
Noun phrases are resolved as they are read, in order, so that pronouns ("it", "them", "inside") and
anaphoric definites ("shut the drawer") refer to the most recent fitting mention. gsr.language.goals
turns the intents into the goal formula.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lark import Token, Tree

from gsr.language.dests import Destinations, token_class, token_value, tree_tokens
from gsr.language.errors import GroundingError
from gsr.language.everyday import Everyday, count_value
from gsr.language.intents import Intent
from gsr.language.lexicon import POSITION_SYNONYMS, Entity
from gsr.language.refs import Description, Place, Ref, Relation, Resolver

#: Mass nouns: "the rubbish" means all of it, not one piece.
MASS_NOUNS = frozenset({"rubbish", "trash", "garbage", "litter", "waste", "debris", "cutlery", "laundry"})


@dataclass(slots=True)
class Interpreter(Destinations, Everyday):
    """Walks one parse tree; keeps the discourse (mentions in order) for pronouns."""

    resolver: Resolver
    mentions: list[Ref] = field(default_factory=list)
    intents: list[Intent] = field(default_factory=list)
    one_head_obj: str | None = None  # the head "one" stands for: "the yellow ones" after "the blue cubes"
    one_head_dest: str | None = None  # ... among destinations: "the top one" after "the bottom drawer"
    _one_head: str | None = None  # inside an exception: the excepting phrase's head
    last_object: Description | None = None  # the last object phrase, for an elided head ("and two in ...")

    @property
    def entities(self) -> dict[str, Entity]:
        """The graph's entity descriptions."""
        return self.resolver.entities

    # ------------------------------------------------------------ commands

    def run(self, tree: Tree) -> list[Intent]:
        """The intents of an instruction's parse tree."""
        for cmd in tree.children:
            if isinstance(cmd, Tree) and cmd.data != "comma":
                self.command(cmd)
        return self.intents

    def command(self, t: Tree) -> None:
        """Interpret one clause."""
        kind = t.data
        trees = [c for c in t.children if isinstance(c, Tree)]
        if self.everyday_command(kind, t, trees):
            return
        if kind == "empty_cmd":  # everything now in (or on) the container goes to the destination
            source = self.np(trees[0])
            # what is in a container (not what stands on its lid), what is on a surface; a container never
            # goes into another container
            rel = "in" if any("container" in self.entities[i].affordances for i in source.ids) else "on"
            inside = tuple(
                x
                for x, (how, where) in self.resolver.support.items()
                if where in self.resolver.with_parts(source.ids)
                and (how == rel or rel == "on")
                and "movable" in self.entities[x].affordances
            )
            if not inside:
                raise GroundingError(
                    f"{source.text!r} is already empty", candidates=source.ids, phrase=source.text
                )
            objs = [Ref(inside, f"what is in {source.text}", plural=True, generic=True)]
            self.mentions.append(objs[0])
            self.intents.append(Intent("place", objs, self.dest(trees[1], objs)))
            return
        if kind == "stack_cmd":
            objs = self.objects(trees[0], "movable")
            for ref in objs:
                self._check_affordance("place", ref)
            dest = self.dest(trees[1], objs) if len(trees) > 1 else None
            ids = [x for r in objs for x in r.ids if dest is None or x != dest.target]
            if len(ids) == 1:
                if dest is None:
                    raise GroundingError(f"stack {ids[0]} on what?", candidates=tuple(ids))
                self.intents.append(Intent("place", objs, dest))
            else:
                self.intents.append(Intent("tower", [Ref(tuple(ids), "the stack", plural=True)], dest))
            return
        if kind == "pick_place_cmd":
            objs_trees = [c for c in trees if c.data in ("objects", "both_list", "np_list")]
            source = next((c for c in trees if c.data == "source"), None)
            picked = self.objects(objs_trees[0], "movable", source=source)
            self.intents.append(Intent("pick", picked))
            placed = picked
            if len(objs_trees) > 1 and not _is_pronoun(objs_trees[1]):
                placed = self.objects(objs_trees[1], "movable")
            # "take X and Y out of A and put them in B", "pick up each cube and put it in B": the pronoun
            # is what was picked up
            dest = self.dest(next(c for c in trees if c.data.startswith("dest_")), placed)
            self.intents.append(Intent("place", placed, dest))
            return
        if kind == "state_cmd":
            self.state(trees)
            return
        verb = {
            "place_cmd": "place",
            "push_cmd": "place",
            "pick_cmd": "pick",
            "open_cmd": "open",
            "close_cmd": "close",
            "turn_on_cmd": "turn_on",
            "turn_off_cmd": "turn_off",
            "press_cmd": "press",
        }[kind]
        need = {
            "place": "movable",
            "pick": "movable",
            "open": "openable",
            "close": "openable",
            "turn_on": "switchable",
            "turn_off": "switchable",
            "press": "pressable",
        }[verb]
        source = next((c for c in trees if c.data == "source"), None)
        objs_tree = next(c for c in trees if c.data in ("objects", "both_list", "np_list"))
        dest_tree = next((c for c in trees if c.data.startswith("dest_")), None)
        objs = self.objects(
            objs_tree, need, source=source
        )  # objects first, also when the destination is fronted
        dest = self.dest(dest_tree, objs) if dest_tree is not None else None
        exception = next((c for c in trees if c.data == "exception"), None)
        if exception is not None:  # "put all the mugs in the box except the red ones"
            objs = self._except(objs, exception)
        for ref in objs:
            self._check_affordance(verb, ref)
        stated = token_class(t.children[0]) == "LEAVE"  # "leave the drawer open": the end state is the goal
        self.intents.append(Intent(verb, objs, dest, stated=stated))
        for gap in (c for c in trees if c.data == "gapped"):  # the verb is elided: same verb, new objects
            parts = [c for c in gap.children if isinstance(c, Tree) and c.data != "comma"]
            gap_objs = self.objects(parts[0], need)
            for ref in gap_objs:
                self._check_affordance(verb, ref)
            self.intents.append(Intent(verb, gap_objs, self.dest(parts[1], gap_objs)))

    def _except(self, objs: list[Ref], exception: Tree) -> list[Ref]:
        d = Description(heads=[(self.one_head_obj or "thing", True)])
        self.exception(exception, d)
        out = [Ref(tuple(i for i in r.ids if i not in d.excluded), r.text, plural=True) for r in objs]
        return [r for r in out if r.ids]

    def state(self, trees: list[Tree]) -> None:
        """``make sure X ends up in Y`` / ``X should be closed``: the stated end state as a goal."""
        subjects = [c for c in trees if c.data in ("objects", "both_list", "np_list")]
        states = [c for c in trees if c.data in ("state_place", "state_flag")]
        for objs_tree, st in zip(subjects, states, strict=True):  # "make sure X is in Y and Z is on"
            self._stated(objs_tree, st)

    def _stated(self, objs_tree: Tree, st: Tree) -> None:
        if st.data == "state_place":
            objs = self.objects(objs_tree, "movable")
            for ref in objs:
                self._check_affordance("place", ref)
            dest = self.dest(next(c for c in st.children if isinstance(c, Tree)), objs)
            self.intents.append(Intent("place", objs, dest))
            return
        classes = [token_class(x) for x in st.children]
        if "ON" in classes or "OFF" in classes:
            verb = "turn_on" if ("ON" in classes) != ("NOT" in classes) else "turn_off"
        else:
            opened = bool({"OPEN", "OPENED"} & set(classes))
            verb = "open" if opened != ("NOT" in classes) else "close"
        need = "switchable" if verb.startswith("turn") else "openable"
        objs = self.objects(objs_tree, need)
        for ref in objs:
            self._check_affordance(verb, ref)
        self.intents.append(Intent(verb, objs, None, stated=True))

    def _check_affordance(self, verb: str, ref: Ref) -> None:
        need = {
            "open": "openable",
            "close": "openable",
            "turn_on": "switchable",
            "turn_off": "switchable",
            "press": "pressable",
            "place": "movable",
            "pick": "movable",
        }[verb]
        bad = [i for i in ref.ids if need not in self.entities[i].affordances]
        if bad and verb == "press":
            return
        if bad:
            words = {"openable": "opened or closed", "switchable": "turned on or off", "movable": "moved"}
            raise GroundingError(
                f"{ref.text!r} ({', '.join(bad)}) cannot be {words.get(need, need)}",
                candidates=tuple(bad),
                phrase=ref.text,
            )

    # ------------------------------------------------------------ noun phrases

    def objects(self, t: Tree, need: str, source: Tree | None = None) -> list[Ref]:
        """The object references of a clause (a list or a single phrase)."""
        nps = [c for c in t.children if isinstance(c, Tree) and c.data != "comma"]
        refs = []
        for np in nps:
            ref = self.np(np, need=need, source=source)
            refs.append(ref)
        if len(refs) > 1:  # "the milk and the popcorn ... them": the list is one mention too
            self.mentions.append(Ref(tuple(i for r in refs for i in r.ids), "them", plural=True))
        return refs

    def np(
        self,
        t: Tree,
        need: str | None = None,
        lenient: bool = False,
        source: Tree | None = None,
        exclude: tuple[str, ...] = (),
        dest: bool = False,
    ) -> Ref:
        """Resolve a noun phrase (records it as a mention unless lenient)."""
        if t.data == "pronoun":
            return self.pronoun(t, need, exclude)
        if t.data in ("partitive_np", "num_np", "everything_np"):
            return self.everyday_np(t, need)
        if t.data in ("place_of", "place_compound"):
            place = self.place(t)
            if isinstance(place, Place):
                raise GroundingError(
                    f"there is no {place.text!r} in the scene to refer to", phrase=place.text
                )
            return place
        d = self.describe(t, dest)
        if source is not None:
            d.relations.append(Relation("from", (self.target(source.children[-1]),)))
        if lenient:
            return self.lenient(d)
        try:
            ref = self._resolve_one(d)
        except GroundingError as exc:
            # "put the cheese in the top drawer and shut the drawer": a definite phrase that fits several
            # objects refers to the one of them already mentioned, if exactly one was (anaphora)
            mentioned = [c for c in exc.candidates if any(m.ids == (c,) for m in self.mentions)]
            if "ambiguous" not in exc.message or len(mentioned) != 1:
                raise
            ref = Ref((mentioned[0],), d.text)
        self.mentions.append(ref)
        head = next((c for c, _ in d.heads if c not in ("thing", "*")), None)
        if head is not None and dest:
            self.one_head_dest = head
        elif head is not None and need is not None:
            self.one_head_obj = head
        if need is not None:
            self.last_object = d
        return ref

    def _resolve_one(self, d: Description) -> Ref:
        """Resolve; "one" standing for an earlier head that fits nothing here is any object ("the red one")."""
        try:
            return self.resolver.resolve(d)
        except GroundingError as exc:
            if not d.one_head or not exc.message.startswith("no object"):
                raise
            d.heads = [("thing", p) for _, p in d.heads]
            return self.resolver.resolve(d)

    def lenient(self, d: Description) -> Ref:
        """All matches of a description (for owners and relation targets, which only filter)."""
        ids: list[str] = []
        for category, _ in d.heads:
            found = self.resolver.candidates(d, category)
            if not d.plural and len(found) > 1:  # "on top of the crate": the crate, if the words say which
                found = self.resolver.best_named(found, d, category)
            ids.extend(e.id for e in found if e.id not in ids)
        if d.entity:
            ids = [d.entity]
        if not ids:
            misses = tuple(i for c, _ in d.heads for i in self.resolver.near_misses(c))
            hint = f" (the nearest kinds in the scene: {', '.join(misses)})" if misses else ""
            raise GroundingError(
                f"no object in the scene matches {d.text!r}{hint}", phrase=d.text, candidates=misses
            )
        ref = Ref(tuple(ids), d.text, plural=len(ids) > 1)
        self.mentions.append(ref)  # "put the cubes of the same colour as the box into it"
        return ref

    def target(self, t: Tree, exclude: tuple[str, ...] = ()) -> Ref | Place:
        """A relation target or owner: a phrase or a place, resolved leniently (pronouns skip ``exclude``)."""
        if t.data in ("place_of", "place_compound"):
            try:
                return self.place(t, exclude)
            except GroundingError as exc:
                if not exc.candidates:
                    raise
                # "the box on top of the other box": a relation target may be any of them
                return Place(exc.candidates, "top", exc.phrase or "")
        if t.data == "pronoun":
            return self.pronoun(t, None, exclude)
        return self.np(t, lenient=True)

    def pronoun(self, t: Tree, need: str | None, exclude: tuple[str, ...]) -> Ref:
        """The most recent mention that fits (an affordance, not one of the clause's own objects)."""
        word = token_value(t.children[0]).text
        plural = word == "them"
        for ref in reversed(self.mentions):
            if set(ref.ids) & set(exclude):
                continue
            if need and any(need not in self.entities[i].affordances for i in ref.ids):
                continue
            if not plural and len(ref.ids) != 1 and not ref.distributive:
                continue
            return Ref(ref.ids, word, plural=plural or len(ref.ids) > 1, forall=ref.forall, count=ref.count)
        raise GroundingError(f"{word!r} does not refer to anything mentioned before it", phrase=word)

    def describe(self, t: Tree, dest: bool = False) -> Description:
        """Read a plain noun phrase into a Description."""
        d = Description(text=" ".join(tok.text for tok in tree_tokens(t)))
        for c in t.children:
            if isinstance(c, Token):
                tok = token_value(c)
                if tok.cls == "ONE":  # "the yellow ones" after "the blue cubes": cubes
                    head = self._one_head or (self.one_head_dest if dest else self.one_head_obj)
                    d.heads.append((head or "thing", tok.plural or tok.text == "ones"))
                    d.one_head = head is not None
                elif tok.cls == "COLORNOUN":  # "the orange": the noun, not the colour
                    d.heads.append((tok.value, tok.plural))
                    if not tok.plural:
                        d.head_words[tok.value] = tok.text
                elif tok.cls == "NAME":  # a name word as the head: any node with that word
                    d.names.append(tok.value)
                    d.heads.append(("*", tok.plural or tok.value in MASS_NOUNS))
                continue
            if c.data == "quant":
                d.quant = {"ALL": "all", "EACH": "each", "BOTH": "both"}[c.children[0].type]
            elif c.data == "det":
                d.indefinite = token_value(c.children[0]).text in ("a", "an", "any")
                d.definite = token_value(c.children[0]).cls in ("POSS",) or token_value(
                    c.children[0]
                ).text in (
                    "the",
                    "these",
                    "those",
                )
            elif c.data == "count":
                d.count = count_value(c)
                d.definite_count = d.definite
                d.indefinite = False
            elif c.data == "premod":
                self._premod(c.children[0], d)
            elif c.data == "heads":
                for h in c.children:
                    if not isinstance(h, Token):
                        continue  # the comma of "cubes, mugs and bowls"
                    tok = token_value(h)
                    if tok.cls == "NOUN":
                        d.heads.append((tok.value, tok.plural))
                        if not tok.plural:
                            d.head_words[tok.value] = tok.text
                    elif tok.cls == "ENTITY":
                        d.entity = tok.value
            else:
                self.postmod(c, d)
        return d

    def postmod(self, c: Tree, d: Description) -> None:
        """A restriction after the head: owner, relation, colour match, exception, name."""
        if c.data == "part_of":
            d.owner = self.target(c.children[-1])
        elif c.data == "postpos":  # "the drawer low": a word of the node's own name, not a position
            d.names.append(token_value(c.children[0]).text)
        elif c.data == "called":  # "the cube called red_cube_3": the node, if it is what the head says
            d.entity = token_value(c.children[-1]).value
        elif c.data == "with_feature":  # "the box with a lid": a word of the object's description
            d.names.append(token_value(c.children[-1]).text)
        elif c.data == "same_color":
            d.same_color_as = self.np([x for x in c.children if isinstance(x, Tree)][-1], lenient=True)
        elif c.data == "rel_color":  # "the box that is blue"
            self._premod(c.children[-1], d)
        elif c.data == "rel_size":
            d.sizes.append(token_value(c.children[-1]).text)
        elif c.data == "rel_state":  # "the drawer that is open"
            d.states.append("open" if token_value(c.children[-1]).cls == "OPENED" else "closed")
        elif c.data == "rel_not_color":  # "every cube that is not yellow"
            d.not_colors.extend(
                token_value(x).value for x in c.children[-1].children if token_value(x).cls == "COLOR"
            )
        elif c.data == "rel_carries":  # "the box that has the yellow box on it"
            np = next(x for x in c.children if isinstance(x, Tree) and x.data != "pronoun")
            d.relations.append(Relation("carries", (self.target(np),)))
        elif c.data == "exception":
            self.exception(c, d)
        elif c.data.startswith("rel_"):
            self._relation(c, d)

    def _premod(self, c: Tree | Token, d: Description) -> None:
        if isinstance(c, Tree) and c.data == "colors":
            d.colors.extend(
                token_value(x).value for x in c.children if token_value(x).cls in ("COLOR", "COLORNOUN")
            )
        elif isinstance(c, Tree) and c.data == "noun_mod":
            d.noun_mods.append(token_value(c.children[0]).value)
        else:
            tok = token_value(c)
            if tok.cls in ("POS", "SIDE"):
                d.positions.append(tok.text)
            elif tok.cls == "SIZE":
                d.sizes.append(tok.text)
            elif tok.cls in ("OPENED", "CLOSED"):
                d.states.append("open" if tok.cls == "OPENED" else "closed")
            elif tok.cls == "OTHER":  # "the other box": not one mentioned before
                d.other_than = {i for m in self.mentions for i in m.ids}
            else:
                d.names.append(tok.value)

    def _relation(self, c: Tree, d: Description) -> None:
        kind = c.data.removeprefix("rel_")
        nps = [x for x in c.children if isinstance(x, Tree)]
        if kind == "pos":  # "the bowl at the back": the same as a position premodifier ("the back bowl")
            d.positions.append(
                next(token_value(x).text for x in c.children if token_class(x) in ("POS", "SIDE"))
            )
            return
        if kind == "side":
            side = nps[0]
            word, owner = self._side(side)
            d.relations.append(Relation("side", (owner,), word))
            return
        d.relations.append(Relation(kind, tuple(self.target(n) for n in nps)))

    def _side(self, t: Tree, exclude: tuple[str, ...] = ()) -> tuple[str, Ref | Place]:
        toks = [x for x in t.children if isinstance(x, Token)]
        owner = self.target([x for x in t.children if isinstance(x, Tree) and x.data != "det"][-1], exclude)
        if t.data == "side_behind":
            return "back", owner
        word = next(token_value(x).text for x in toks if token_value(x).cls in ("SIDE", "POS"))
        return POSITION_SYNONYMS.get(word, word), owner

    def place(self, t: Tree, exclude: tuple[str, ...] = ()) -> Ref | Place:
        """``the top of the cabinet`` / ``the table center``: a part or region node, else a Place."""
        toks = [token_value(x) for x in t.children if isinstance(x, Token)]
        pos = POSITION_SYNONYMS.get(
            next(x.text for x in toks if x.cls == "POS"), next(x.text for x in toks if x.cls == "POS")
        )
        if t.data == "place_of":
            # "put the bowl on top of it": "it" is not the bowl itself
            owner_ref = self.target(
                [x for x in t.children if isinstance(x, Tree) and x.data != "det"][-1], exclude
            )
            owner = owner_ref.ids if isinstance(owner_ref, Ref) else owner_ref.owner
        else:
            noun = next(x for x in toks if x.cls == "NOUN")
            owner = tuple(
                e.id for e in self.resolver.candidates(Description(heads=[(noun.value, False)]), noun.value)
            )
        text = " ".join(x.text for x in tree_tokens(t))
        found = self.resolver.regions(owner, pos)
        if not found and t.data == "place_of":  # "the top of the drawer": its owner's top
            parents = tuple({self.entities[o].parent for o in owner} - {None})
            found = self.resolver.regions(parents, pos) if parents else []
        if len(found) == 1:
            return Ref((found[0],), text)
        if len(found) > 1:
            raise GroundingError(
                f"{text!r} is ambiguous: it could be any of {', '.join(found)}",
                candidates=tuple(found),
                phrase=text,
            )
        if pos == "top" and owner and all("supporter" in self.entities[o].affordances for o in owner):
            if len(owner) == 1:
                return Ref(owner, text)
            # "on top of the wine rack" with two racks: which one is not said
            raise GroundingError(
                f"{text!r} is ambiguous: it could be on any of {', '.join(owner)}",
                candidates=tuple(owner),
                phrase=text,
            )
        return Place(owner, pos, text)


def _is_pronoun(t: Tree) -> bool:
    """An object list that is just ``it`` / ``them``."""
    kids = [c for c in t.children if isinstance(c, Tree)]
    return len(kids) == 1 and kids[0].data == "pronoun"
