"""LIBERO BDDL task -> scene graph + tabletop-domain problem.

LIBERO places objects in *regions* (``kitchen_table_akita_black_bowl_init_region``,
``wooden_cabinet_1_top_region``, ``basket_1_contain_region``). The tabletop domain speaks about
objects and their parts instead, so each region reference is resolved to a node:

* a region on a table or the floor where the scene places something (an ``:init`` fact names it:
  ``main_table_plate_region``) collapses onto the table (``on`` the table itself; the object keeps the
  region's name as its ``region`` attribute); a table region where nothing starts
  (``main_table_stove_front_region``, ``living_room_table_plate_right_region``) is a ``region`` part
  of the table that objects can be pushed or placed onto;
* ``top_region`` / ``middle_region`` / ``bottom_region`` of a cabinet are drawer parts
  (``wooden_cabinet_1/top_drawer``, levels 2/1/0); ``top_side`` is the cabinet's top surface;
* ``contain_region`` (basket, tray), ``heating_region`` (microwave), ``cook_region`` (stove) and
  ``top_region`` of a rack collapse onto their object; ``back_contain_region`` of a caddy is the part
  ``desk_caddy_1/back_compartment``; other regions of objects become parts (``compartment`` when an
  ``:init`` fact puts something *in* them or their owner is a container, else ``region``).

The scene graph is built from the scene alone (``:regions``, ``:fixtures``, ``:objects``, ``:init``),
never from ``:goal``: an agent that sees the graph learns nothing about the task's answer. A goal atom
``In`` a ``region`` part (or ``On`` a ``compartment``) is read with the part's own predicate.

Predicates: On->on, In->in, Open->open, Close->(not open), TurnOn->turned_on, TurnOff->(not turned_on).
The mapping is documented in docs/tabletop-domain.md.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

from gsr.categories import category_of, is_a
from gsr.errors import GSRError
from gsr.facts import node_affordances, problem_from_graph
from gsr.pddl.model import And, Atom, Domain, Exists, Forall, Formula, Imply, Not, Or, Problem, is_variable
from gsr.scene_graph import Edge, Node, SceneGraph

if TYPE_CHECKING:
    from gsr.pddl.bddl import BddlProblem, Region

_DRAWER_REGION = re.compile(r"^(top|upper|high|middle|mid|bottom|lower|low)_region$")
_DRAWER_LEVEL = {"top": 2, "upper": 2, "high": 2, "middle": 1, "mid": 1, "bottom": 0, "lower": 0, "low": 0}
_DRAWER_WORD = {2: "top", 1: "middle", 0: "bottom"}
#: Regions that are simply the object itself (its interior or its working surface).
_COLLAPSING = {"contain_region", "heating_region", "cook_region"}
_SURFACES = ("table", "floor")
_SUPPORT = {"on": "on", "in": "in"}


@dataclass(frozen=True, slots=True)
class _Target:
    """Where a region reference points: a node id (an entity or a part)."""

    node: str
    part: Node | None = None  # the part node to create, if the region is a part


def _category(type_name: str) -> tuple[str, dict[str, str | int]]:
    category, attrs = category_of(type_name)
    attrs.pop("level", None)
    return category, attrs


def _is_surface(category: str) -> bool:
    return any(is_a(category, s) for s in _SURFACES)


def _is_container(category: str) -> bool:
    """Whether things of this category go *in* it (a caddy, a basket), by its affordances."""
    return "container" in node_affordances(Node(id="owner", category=category))


class _Converter:
    """One BDDL problem's conversion state."""

    def __init__(self, bddl: BddlProblem) -> None:
        self.bddl = bddl
        self.where = f"LIBERO problem {bddl.name}"
        self.entities: dict[
            str, tuple[str, str, dict[str, str | int], bool]
        ] = {}  # id -> type, cat, attrs, fixture
        for fixture, (kind, is_fixture) in [(n, (t, True)) for n, t in bddl.fixtures.items()] + [
            (n, (t, False)) for n, t in bddl.objects.items()
        ]:
            cat, attrs = _category(kind)
            self.entities[fixture.lower()] = (kind.lower(), cat, attrs, is_fixture)
        # what the scene's :init says about each region: the scene graph never looks at :goal
        self.init_refs = {a.lower() for atom in bddl.init for a in atom.args}
        self.in_refs = {
            atom.args[1].lower() for atom in bddl.init if atom.predicate == "in" and len(atom.args) == 2
        }
        self.targets: dict[str, _Target] = {}
        self.parts: dict[str, Node] = {}
        self.surface_regions: dict[str, str] = {}  # collapsed table/floor region ref -> region name
        self.placed: dict[str, str] = {}  # object -> the surface region it starts on
        for region in bddl.regions:
            self._add_region(region)

    # ---------------------------------------------------------------- regions

    def _add_region(self, region: Region) -> None:
        target, name = region.target.lower(), region.name.lower()
        ref = f"{target}_{name}"
        if target not in self.entities or ref in self.targets:
            return  # LIBERO declares regions of absent objects (bowl_drainer_1): harmless unless referenced
        _, cat, _, _ = self.entities[target]
        if _is_surface(cat):
            if ref not in self.init_refs:  # a place on the table where nothing starts: a region part
                self._part(ref, target, name, "region")
            else:
                self.targets[ref] = _Target(target)
                # keep where on the surface an object starts ("between_plate_ramekin", "table_center"):
                # instructions refer to objects by it ("the bowl between the plate and the ramekin")
                self.surface_regions[ref] = name.removesuffix("_region")
        elif is_a(cat, "cabinet") and _DRAWER_REGION.match(name):
            level = _DRAWER_LEVEL[name.split("_", 1)[0]]
            self._part(ref, target, f"{_DRAWER_WORD[level]}_drawer", "drawer", level=level)
        elif name == "top_side":
            self._part(ref, target, "top_side", "cabinet_top" if is_a(cat, "cabinet") else "region")
        elif name in _COLLAPSING or (is_a(cat, "rack") and name == "top_region"):
            self.targets[ref] = _Target(target)
        elif name.endswith("_contain_region"):
            self._part(ref, target, name.removesuffix("_contain_region") + "_compartment", "compartment")
        else:
            inside = ref in self.in_refs or _is_container(cat)
            self._part(ref, target, name, "compartment" if inside else "region")

    def _part(self, ref: str, parent: str, part_name: str, category: str, level: int | None = None) -> None:
        node_id = f"{parent}/{part_name}"
        attrs: dict[str, str | int | bool] = {"libero_region": ref}
        if level is not None:
            attrs["level"] = level
        node = Node(id=node_id, category=category, attributes=attrs, parent=parent)
        self.parts.setdefault(node_id, node)
        self.targets[ref] = _Target(node_id, node)

    def resolve(self, ref: str) -> str:
        """The node a BDDL name (object, fixture or region reference) denotes."""
        ref = ref.lower()
        if ref in self.entities:
            return ref
        if ref in self.targets:
            return self.targets[ref].node
        raise GSRError(f"{self.where}: unknown object or region {ref!r}")

    # ---------------------------------------------------------------- graph

    def graph(self) -> SceneGraph:
        """The initial scene graph."""
        states: dict[str, set[str]] = {}
        support: dict[str, Edge] = {}
        for atom in self.bddl.init:
            self._init_atom(atom, states, support)
        nodes: list[Node] = []
        for name, (kind, cat, attrs, fixture) in self.entities.items():
            full: dict[str, str | int | float | bool] = {**attrs, "asset": kind}
            if name in self.placed:
                full["region"] = self.placed[name]
            if fixture:
                full["fixture"] = True
                full["movable"] = False  # LIBERO fixtures are bolted to the scene
            nodes.append(Node(id=name, category=cat, attributes=full, states=tuple(states.get(name, ()))))
            nodes.extend(p for p in self.parts.values() if p.parent == name)
        nodes = [self._default_state(n, states) for n in nodes]
        surface = next((n for n, (_, c, _, _) in self.entities.items() if is_a(c, "table")), None) or next(
            (n for n, (_, c, _, _) in self.entities.items() if is_a(c, "floor")), None
        )
        edges = list(support.values())
        for name, (_, cat, _, _) in self.entities.items():
            if name not in support and not _is_surface(cat) and surface is not None:
                edges.append(Edge(source=name, relation="on", target=surface))
        metadata = {"source": "libero", "problem": self.bddl.name, "language": self.bddl.language}
        return SceneGraph(nodes=tuple(nodes), edges=tuple(edges), metadata=metadata)

    def _default_state(self, node: Node, states: dict[str, set[str]]) -> Node:
        extra = set(states.get(node.id, ()))
        aff = node_affordances(node)
        if "openable" in aff and not extra & {"open", "closed"}:
            extra.add("closed")  # LIBERO drawers and doors start closed unless (Open x) says otherwise
        if "switchable" in aff and not extra & {"on", "off"}:
            extra.add("off")
        return node.model_copy(update={"states": tuple(sorted(extra))}) if extra != set(node.states) else node

    def _init_atom(self, atom: Atom, states: dict[str, set[str]], support: dict[str, Edge]) -> None:
        pred = atom.predicate
        if pred in _SUPPORT and len(atom.args) == 2:
            obj, where = self.resolve(atom.args[0]), self.resolve(atom.args[1])
            if obj != where and obj not in support:
                support[obj] = Edge(source=obj, relation=_SUPPORT[pred], target=where)
                if atom.args[1].lower() in self.surface_regions:
                    self.placed[obj] = self.surface_regions[atom.args[1].lower()]
        elif pred in ("open", "close") and len(atom.args) == 1:
            node = self.resolve(atom.args[0])
            states.setdefault(node, set()).add("open" if pred == "open" else "closed")
        elif pred in ("turnon", "turnoff") and len(atom.args) == 1:
            node = self.resolve(atom.args[0])
            states.setdefault(node, set()).add("on" if pred == "turnon" else "off")
        else:
            raise GSRError(f"{self.where}: unsupported init fact {atom}")

    # ---------------------------------------------------------------- goal

    def goal(self, formula: Formula) -> Formula:
        """The BDDL goal in tabletop-domain terms."""
        if isinstance(formula, Atom):
            return self._goal_atom(formula)
        if isinstance(formula, Not):
            return Not(self.goal(formula.formula))
        if isinstance(formula, And):
            return And(tuple(self.goal(p) for p in formula.parts))
        if isinstance(formula, Or):
            return Or(tuple(self.goal(p) for p in formula.parts))
        if isinstance(formula, Imply):
            return Imply(self.goal(formula.condition), self.goal(formula.then))
        if isinstance(formula, Exists):
            return Exists(formula.params, self.goal(formula.body))
        if isinstance(formula, Forall):
            return Forall(formula.params, self.goal(formula.body))
        raise GSRError(f"{self.where}: unsupported goal construct {type(formula).__name__}")

    def _arg(self, term: str) -> str:
        return term if is_variable(term) else self.resolve(term)

    def _goal_atom(self, atom: Atom) -> Formula:
        args = tuple(self._arg(a) for a in atom.args)
        pred = atom.predicate
        if pred in _SUPPORT and len(args) == 2:
            # the part's own predicate: a goal "In" a region part is "on" it, "On" a compartment is "in" it
            part = self.parts.get(args[1])
            if part is not None and part.category in ("region", "compartment"):
                return Atom("in" if part.category == "compartment" else "on", args)
            return Atom(_SUPPORT[pred], args)
        if pred == "open" and len(args) == 1:
            return Atom("open", args)
        if pred == "close" and len(args) == 1:
            return Not(Atom("open", args))
        if pred == "turnon" and len(args) == 1:
            return Atom("turned_on", args)
        if pred == "turnoff" and len(args) == 1:
            return Not(Atom("turned_on", args))
        raise GSRError(f"{self.where}: unsupported goal predicate in {atom}")


def libero_graph(bddl: BddlProblem) -> SceneGraph:
    """The initial scene graph of a LIBERO task."""
    return _Converter(bddl).graph()


def libero_task(bddl: BddlProblem, domain: Domain | None = None) -> tuple[SceneGraph, Problem]:
    """A LIBERO task as ``(initial scene graph, tabletop-domain problem)``."""
    conv = _Converter(bddl)
    graph = conv.graph()
    goal = conv.goal(bddl.goal)
    return graph, problem_from_graph(graph, goal, name=bddl.name, domain=domain)
