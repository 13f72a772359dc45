"""Everyday constructions of the Interpreter: counts, "everything", exceptions, fill/give/by clauses.

A mixin of :class:`gsr.language.build.Interpreter` (which supplies np, objects, describe, dest,
mentions): exact counts ("2 blue cubes", "a couple of mugs", "three of the red cubes", an elided
"two" after "one red cube"), "everything (blue)", "except X", "fill Y with X", "give each cube its
own drawer", "clear the table by putting ...", "put each colour of cube in its own drawer".
"""

from __future__ import annotations

from dataclasses import replace

from lark import Token, Tree

from gsr.language.dests import token_value, tree_tokens
from gsr.language.errors import GroundingError
from gsr.language.intents import Dest, Intent
from gsr.language.lexicon import number_value
from gsr.language.refs import Description, Ref


def count_value(t: Tree) -> int:
    """The number of a ``count`` subtree (NUM or ONE)."""
    tok = token_value(t.children[0])
    if tok.cls == "ONE":
        return 1
    n = number_value(tok.value)
    if n is None or n < 1:
        raise GroundingError(f"{tok.text!r} is not a count of objects", phrase=tok.text)
    return n


class Everyday:
    """Counted and quantified phrases and the fill/give/by clauses for the Interpreter."""

    def everyday_np(self, t: Tree, need: str | None) -> Ref:
        """``partitive_np`` / ``num_np`` / ``everything_np``."""
        if t.data == "partitive_np":  # "three of the red cubes": a count among the phrase's matches
            n = count_value(t.children[0])
            inner = self.np(t.children[-1], need=need)
            if len(inner.ids) < n:
                raise GroundingError(
                    f"{inner.text!r} has only {len(inner.ids)}, not {n}",
                    candidates=inner.ids,
                    phrase=inner.text,
                )
            ref = Ref(
                inner.ids,
                " ".join(x.text for x in tree_tokens(t)),
                plural=True,
                count=n if n < len(inner.ids) else None,
            )
            self.mentions.append(ref)
            return ref
        if t.data == "num_np":  # "... and two in the blue box": the last object phrase, counted anew
            tok = token_value(t.children[0])
            n = number_value(tok.value)
            last = getattr(self, "last_object", None)
            if last is None or n is None:
                raise GroundingError(
                    f"{tok.text!r}: two of what? no object phrase before it", phrase=tok.text
                )
            d = replace(last, count=n, definite_count=False, indefinite=False, quant=None, text=tok.text)
            d.heads = [(c, True) for c, _ in last.heads]
            ref = self.resolver.resolve(d)
            self.mentions.append(ref)
            return ref
        # "everything", "everything blue", "everything except the ketchup", "everything on the table"
        d = Description(text=" ".join(x.text for x in tree_tokens(t)), heads=[("thing", True)], quant="all")
        self._one_head = "thing"
        for c in t.children:
            if isinstance(c, Tree) and c.data == "colors":
                d.colors.extend(
                    token_value(x).value for x in c.children if token_value(x).cls in ("COLOR", "COLORNOUN")
                )
            elif isinstance(c, Tree):
                self.postmod(c, d)
        ref = self.resolver.resolve(d)
        ref = replace(ref, generic=True)
        self.mentions.append(ref)
        return ref

    def exception(self, t: Tree, d: Description) -> None:
        """``except the porcelain one``: the excepted objects (``one`` is the phrase's own kind)."""
        saved = getattr(self, "_one_head", None)
        self._one_head = d.heads[0][0] if d.heads and d.heads[0][0] not in ("*",) else saved
        try:
            ex = self.np(t.children[-1], lenient=True)
        finally:
            self._one_head = saved
        d.excluded |= set(ex.ids)

    def everyday_command(self, kind: str, t: Tree, trees: list[Tree]) -> bool:
        """The fill/give/by/each-colour clauses; False for other kinds."""
        if kind == "by_cmd":  # "clear the table by putting everything in the box": the means is the goal
            self.command(next(c for c in trees if c.data.endswith("_cmd") or c.data == "place_color_cmd"))
            return True
        if kind == "fill_cmd":  # "fill the blue box with the red cubes"
            container = self.np(trees[0])
            objs = self.objects(trees[1], "movable")
            for ref in objs:
                self._check_affordance("place", ref)
            self.intents.append(Intent("place", objs, self._at(container, "in")))
            return True
        if kind == "give_cmd":  # "give each cube its own drawer": different ones
            objs = self.objects(trees[0], "movable")
            nominal = next(c for c in trees if c.data == "nominal")
            category = [
                token_value(x).value
                for x in nominal.children
                if isinstance(x, Token) and token_value(x).cls == "NOUN"
            ][-1]
            self.intents.append(Intent("place", objs, Dest("different", "in", category=category)))
            return True
        if kind == "place_color_cmd":  # "put each colour of cube in its own drawer": one colour per drawer
            objs = []
            for np in (c for c in trees[0].children if isinstance(c, Tree) and c.data != "comma"):
                d = self.describe(np)  # "each colour of cube": the kind, all of them
                d.heads = [(c, True) for c, _ in d.heads]
                objs.append(self.resolver.resolve(d))
            dest = self.dest(next(c for c in trees if c.data.startswith("dest_")), objs)
            if dest.kind not in ("different", "by_color"):
                raise GroundingError("each colour needs a place of its own (say 'in its own drawer')")
            self.intents.append(
                Intent("place", objs, Dest("by_color", "in", category=dest.category, owner=dest.owner))
            )
            return True
        return False
