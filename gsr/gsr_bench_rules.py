"""GSR-Bench's action rules on a scene graph: typed verdicts for ``move``/``open``/``close`` commands and replay.

This is the rule set of the benchmark's own validator (``langgraph_agent/tools/
action_validation_execution_tool.py`` in KLMmotion/GSR-bench), which accepts or rejects each command
an agent sends, re-stated on GSR's :class:`~gsr.scene_graph.SceneGraph`. A command is checked in the
validator's order and the first broken rule is reported as a :class:`Rule`:

``move X in|into|on|to|upon Y`` (``put`` is a synonym; ``to``/``upon`` mean ``on``):

1. ``X`` and ``Y`` are objects of the scene (``Y`` may be ``table``)            -> ``unknown_object``
2. a cube must stand on the table or be in something: a cube *on* anything but the table is stuck
   (the validator counts the cube itself among what lies on its support), and a cube in a container
   with something on the container cannot be taken                            -> ``source_unlocated``,
   ``source_container_blocked``
3. nothing lies on ``X``                                                        -> ``source_blocked``
4. if ``X`` is in a container: the container is not closed, a drawer is open and no drawer above it
   is open, and nothing lies on the container       -> ``source_container_closed``, ``drawer_order``,
   ``source_container_blocked``
5. (``Y`` not the table) ``X`` and ``Y`` are not both containers (boxes, lidded boxes, drawers), in
   *or* on                                                                     -> ``container_in_container``
6. (``Y`` not the table) ``Y`` is not a cube or a mug                          -> ``not_a_support``
7. (``Y`` not the table) nothing lies on ``Y``; a lidded box or drawer ``Y`` is not closed, a drawer
   ``Y`` is open with no drawer above it open                 -> ``target_blocked``, ``target_closed``,
   ``drawer_order``
8. (``X`` a cube, ``Y`` not the table) ``Y`` holds fewer than 10 cubes          -> ``cube_capacity``
   (``Y`` the table) the table is not full (a ``0=F`` status edge)              -> ``table_full``
9. the result does not hold already (``X`` already ``rel`` ``Y``; on the table for a table move)
                                                                               -> ``already_done``

``open X`` / ``close X``: ``X`` exists (``unknown_object``), has an open/closed state (``not_openable``)
and is not already in the asked state (``already_done``). The validator checks nothing else for them
(no blocking, no drawer order).

Object classes are the benchmark's own, read from names as it does: a cube has ``cube`` in its name,
a mug ``mug``; containers are names with ``drawer`` or ``lid_box`` or ending in ``_box``. Drawer
order uses the drawers' ``level`` attributes within one cabinet (the benchmark's single cabinet
``short_cabinet`` has ``drawer_low`` < ``drawer_middle`` < ``drawer_high``).

Replay (:func:`apply_command`): a valid move replaces ``X``'s support edges by ``X rel Y`` (``X on
table`` for the table), carrying what is inside ``X`` along; ``open``/``close`` set the node's state.
The table-full status is part of the given scene and is not recomputed.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from enum import StrEnum

from gsr.errors import GSRError
from gsr.scene_graph import Edge, Node, SceneGraph

TABLE = "table"
#: The benchmark's cube capacity: a container holding this many cubes takes no more.
CUBE_CAPACITY = 10
#: Node state that marks the table full (a ``0=F`` status edge in a GSR-Bench message).
TABLE_FULL_STATE = "full"

_NAME = r"([a-z_][a-z0-9_/]*)"
_PREFIX = r"(?:action\s+type\s+\d+\s*:\s*)?"
_OPEN_CLOSE = re.compile(_PREFIX + r"(open|close)\s+" + _NAME)
_MOVE = re.compile(_PREFIX + r"(?:move|put)\s+" + _NAME + r"\s+(in|into|to|on|upon)\s+" + _NAME)
_RELATION = {"in": "in", "into": "in", "on": "on", "to": "on", "upon": "on"}


class Rule(StrEnum):
    """Which GSR-Bench rule a command breaks."""

    UNPARSABLE = "unparsable_command"
    UNKNOWN_OBJECT = "unknown_object"
    SOURCE_UNLOCATED = "source_unlocated"
    SOURCE_BLOCKED = "source_blocked"
    SOURCE_CONTAINER_CLOSED = "source_container_closed"
    SOURCE_CONTAINER_BLOCKED = "source_container_blocked"
    DRAWER_ORDER = "drawer_order"
    CONTAINER_IN_CONTAINER = "container_in_container"
    NOT_A_SUPPORT = "not_a_support"
    TARGET_BLOCKED = "target_blocked"
    TARGET_CLOSED = "target_closed"
    CUBE_CAPACITY = "cube_capacity"
    TABLE_FULL = "table_full"
    ALREADY_DONE = "already_done"
    NOT_OPENABLE = "not_openable"


@dataclass(frozen=True)
class Command:
    """A parsed command: ``verb`` is move, open or close; ``relation`` is in/on for moves."""

    verb: str
    obj: str
    relation: str | None = None
    target: str | None = None

    def __str__(self) -> str:
        if self.verb == "move":
            return f"move {self.obj} {self.relation} {self.target}"
        return f"{self.verb} {self.obj}"


@dataclass(frozen=True)
class Verdict:
    """The outcome of one command: ok, or the broken rule and a sentence naming the objects involved."""

    ok: bool
    command: str
    rule: Rule | None = None
    message: str = ""
    objects: tuple[str, ...] = field(default=())

    def to_dict(self) -> dict[str, object]:
        """JSON-friendly form."""
        out: dict[str, object] = {"ok": self.ok, "command": self.command, "message": self.message}
        if self.rule is not None:
            out["rule"] = self.rule.value
        if self.objects:
            out["objects"] = list(self.objects)
        return out


def parse_command(text: str) -> Command | None:
    """``move red_cube1 into red_box`` -> Command; None when the text is not a GSR-Bench command.

    As the benchmark, the command is lower-cased and matched at its start (trailing text is ignored);
    an optional ``action type N:`` prefix is allowed.
    """
    if not isinstance(text, str):
        return None
    text = text.strip().lower()
    m = _OPEN_CLOSE.match(text)
    if m:
        return Command(m.group(1), m.group(2))
    m = _MOVE.match(text)
    if m:
        return Command("move", m.group(1), _RELATION[m.group(2)], m.group(3))
    return None


# ------------------------------------------------------------ object classes (the benchmark's, by name)


def is_cube(name: str) -> bool:
    """GSR-Bench cubes: ``cube`` in the name."""
    return "cube" in name


def is_mug(name: str) -> bool:
    """GSR-Bench mugs: ``mug`` in the name."""
    return "mug" in name


def is_lidded(name: str) -> bool:
    """Lidded boxes: ``lid_box`` in the name."""
    return "lid_box" in name


def is_drawer(name: str) -> bool:
    """Drawers: ``drawer`` in the name."""
    return "drawer" in name


def is_container(name: str) -> bool:
    """GSR-Bench containers: drawers, lidded boxes and ``*_box``."""
    return is_drawer(name) or is_lidded(name) or name.endswith("_box")


# ------------------------------------------------------------ scene queries


class _Scene:
    """Indexes of one graph for the rule checks."""

    def __init__(self, graph: SceneGraph) -> None:
        self.graph = graph
        self.nodes = graph.node_map()
        self.on_top: dict[str, list[str]] = {}
        self.support: dict[str, Edge] = {}
        self.inside: dict[str, list[str]] = {}
        self.container_of: dict[
            str, str
        ] = {}  # the first ``in`` edge of an object, as the validator reads it
        for e in graph.edges:
            if e.relation == "on":
                self.on_top.setdefault(e.target, []).append(e.source)
            if e.relation in ("on", "in"):
                self.support.setdefault(e.source, e)
            if e.relation == "in":
                self.inside.setdefault(e.target, []).append(e.source)
                self.container_of.setdefault(e.source, e.target)

    def state(self, name: str) -> str | None:
        node = self.nodes.get(name)
        if node is None:
            return None
        if "open" in node.states:
            return "open"
        if "closed" in node.states:
            return "closed"
        return None

    def upper_open_drawers(self, drawer: str) -> list[str]:
        """Open drawers of the same cabinet above ``drawer`` (by ``level``)."""
        node = self.nodes.get(drawer)
        level = _level(node)
        if node is None or node.parent is None or level is None:
            return []
        out = []
        for other in self.graph.nodes:
            if other.id != drawer and other.parent == node.parent and is_drawer(other.id):
                lv = _level(other)
                if lv is not None and lv > level and self.state(other.id) == "open":
                    out.append(other.id)
        return out

    def table_full(self) -> bool:
        table = self.nodes.get(TABLE)
        return table is not None and TABLE_FULL_STATE in table.states


def _level(node: Node | None) -> int | None:
    if node is None:
        return None
    level = node.attributes.get("level")
    if isinstance(level, bool) or not isinstance(level, int | float):
        return None
    return int(level)


def _reject(command: str, rule: Rule, message: str, *objects: str) -> Verdict:
    return Verdict(False, command, rule, message, tuple(objects))


def _drawer_reachable(scene: _Scene, command: str, drawer: str, closed_rule: Rule) -> Verdict | None:
    if scene.state(drawer) != "open":
        return _reject(command, closed_rule, f"{drawer} is not open: open {drawer} first", drawer)
    upper = scene.upper_open_drawers(drawer)
    if upper:
        return _reject(
            command,
            Rule.DRAWER_ORDER,
            f"{drawer} cannot be reached while {', '.join(upper)} above it is open: close it first",
            drawer,
            *upper,
        )
    return None


def check_command(graph: SceneGraph, command: str | Command) -> Verdict:
    """Is ``command`` accepted by GSR-Bench's validator in ``graph``? The first broken rule otherwise."""
    return _check(_Scene(graph), command)


def _check(scene: _Scene, command: str | Command) -> Verdict:
    cmd = parse_command(command) if isinstance(command, str) else command
    text = command if isinstance(command, str) else str(command)
    if cmd is None:
        return _reject(
            text, Rule.UNPARSABLE, f"cannot parse {text!r}: use 'move X in|on Y', 'open X' or 'close X'"
        )
    if cmd.verb in ("open", "close"):
        return _check_open_close(scene, text, cmd)
    return _check_move(scene, text, cmd)


def _check_open_close(scene: _Scene, text: str, cmd: Command) -> Verdict:
    x = cmd.obj
    if x not in scene.nodes:
        return _reject(text, Rule.UNKNOWN_OBJECT, f"{x} is not in the scene", x)
    state = scene.state(x)
    if state is None:
        return _reject(text, Rule.NOT_OPENABLE, f"{x} has no open/closed state", x)
    wanted = "open" if cmd.verb == "open" else "closed"
    if state == wanted:
        return _reject(text, Rule.ALREADY_DONE, f"{x} is already {wanted}", x)
    return Verdict(True, text, message=f"{text}: ok")


def _check_move(scene: _Scene, text: str, cmd: Command) -> Verdict:
    x, y, rel = cmd.obj, cmd.target or "", cmd.relation or "on"
    objects = set(scene.nodes) - {TABLE}
    if x not in objects:
        return _reject(text, Rule.UNKNOWN_OBJECT, f"{x} is not an object of the scene", x)
    if y != TABLE and y not in objects:
        return _reject(text, Rule.UNKNOWN_OBJECT, f"{y} is not an object of the scene", y)
    if is_cube(x):
        support = scene.support.get(x)
        if support is None:
            return _reject(text, Rule.SOURCE_UNLOCATED, f"{x} is neither on nor in anything", x)
        if support.target != TABLE:
            blockers = scene.on_top.get(support.target, [])
            if blockers:
                what = "its own support" if blockers == [x] else ", ".join(blockers)
                return _reject(
                    text,
                    Rule.SOURCE_CONTAINER_BLOCKED,
                    f"{x} is {support.relation} {support.target}, which is covered ({what}): "
                    "a cube can be taken from the table or from inside an uncovered container",
                    x,
                    support.target,
                    *blockers,
                )
    above = scene.on_top.get(x, [])
    if above:
        return _reject(
            text, Rule.SOURCE_BLOCKED, f"{x} has {', '.join(above)} on top: clear it first", x, *above
        )
    holder = scene.container_of.get(x)
    if holder is not None:
        if scene.state(holder) == "closed":
            return _reject(
                text,
                Rule.SOURCE_CONTAINER_CLOSED,
                f"{x} is in {holder}, which is closed: open {holder} first",
                x,
                holder,
            )
        if is_drawer(holder):
            bad = _drawer_reachable(scene, text, holder, Rule.SOURCE_CONTAINER_CLOSED)
            if bad is not None:
                return bad
        covering = scene.on_top.get(holder, [])
        if covering:
            return _reject(
                text,
                Rule.SOURCE_CONTAINER_BLOCKED,
                f"{x} is in {holder}, which has {', '.join(covering)} on top: clear it first",
                x,
                holder,
                *covering,
            )
    if y != TABLE:
        if is_container(x) and is_container(y):
            return _reject(
                text,
                Rule.CONTAINER_IN_CONTAINER,
                f"{x} and {y} are both containers: no container goes in or on another",
                x,
                y,
            )
        if is_cube(y) or is_mug(y):
            kind = "cube" if is_cube(y) else "mug"
            return _reject(text, Rule.NOT_A_SUPPORT, f"nothing can be put on the {kind} {y}", y)
        covering = scene.on_top.get(y, [])
        if covering:
            return _reject(
                text,
                Rule.TARGET_BLOCKED,
                f"{y} has {', '.join(covering)} on top: clear it first",
                y,
                *covering,
            )
        if is_lidded(y) or is_drawer(y):
            if scene.state(y) == "closed":
                return _reject(text, Rule.TARGET_CLOSED, f"{y} is closed: open {y} first", y)
            if is_drawer(y):
                bad = _drawer_reachable(scene, text, y, Rule.TARGET_CLOSED)
                if bad is not None:
                    return bad
        if is_cube(x):
            cubes = sum(1 for o in scene.inside.get(y, []) if is_cube(o))
            if cubes >= CUBE_CAPACITY:
                return _reject(
                    text, Rule.CUBE_CAPACITY, f"{y} already holds {cubes} cubes (at most {CUBE_CAPACITY})", y
                )
    elif scene.table_full():
        return _reject(text, Rule.TABLE_FULL, "the table is full", TABLE)
    done = any(e.source == x and e.relation == rel and e.target == y for e in scene.graph.edges)
    if y == TABLE:
        done = done or any(
            e.source == x and e.relation == "on" and e.target == TABLE for e in scene.graph.edges
        )
    if done:
        where = "on the table" if y == TABLE else f"{rel} {y}"
        return _reject(text, Rule.ALREADY_DONE, f"{x} is already {where}", x)
    return Verdict(True, text, message=f"{text}: ok")


# ------------------------------------------------------------ replay


def apply_command(graph: SceneGraph, command: str | Command) -> SceneGraph:
    """The graph after a command the validator accepts (GSRError naming the rule otherwise)."""
    cmd = parse_command(command) if isinstance(command, str) else command
    verdict = check_command(graph, command)
    if not verdict.ok or cmd is None:
        raise GSRError(
            f"{verdict.command}: rejected ({verdict.rule.value if verdict.rule else '?'}): {verdict.message}"
        )
    return transition(graph, cmd)


def transition(graph: SceneGraph, cmd: Command) -> SceneGraph:
    """The graph after a parsed command, without checking it (see :func:`apply_command`)."""
    if cmd.verb in ("open", "close"):
        new = "open" if cmd.verb == "open" else "closed"
        nodes = []
        for n in graph.nodes:
            if n.id == cmd.obj:
                states = (*tuple(s for s in n.states if s not in ("open", "closed")), new)
                n = n.model_copy(update={"states": tuple(sorted(states))})
            nodes.append(n)
        return graph.model_copy(update={"nodes": tuple(nodes)})
    x, y = cmd.obj, cmd.target or TABLE
    rel = "on" if y == TABLE else (cmd.relation or "on")
    if x == y:
        raise GSRError(f"{cmd}: an object cannot be put {rel} itself")
    if y not in graph.node_map():
        raise GSRError(f"{cmd}: the scene has no {y} node")
    edges = [e for e in graph.edges if not (e.source == x and e.relation in ("on", "in"))]
    edges.append(Edge(source=x, relation=rel, target=y))
    return SceneGraph(nodes=graph.nodes, edges=tuple(edges), metadata=graph.metadata)


@dataclass(frozen=True)
class Replay:
    """Commands replayed under the rules: the verdicts up to the first rejection and the final graph."""

    verdicts: tuple[Verdict, ...]
    graph: SceneGraph

    @property
    def ok(self) -> bool:
        """True when every command was accepted."""
        return all(v.ok for v in self.verdicts)

    @property
    def rejected(self) -> Verdict | None:
        """The first rejected command's verdict, if any."""
        return next((v for v in self.verdicts if not v.ok), None)


def replay(graph: SceneGraph, commands: Iterable[str | Command]) -> Replay:
    """Check and apply commands in order; stops at the first rejected one (the graph is the state before it)."""
    verdicts: list[Verdict] = []
    for command in commands:
        cmd = parse_command(command) if isinstance(command, str) else command
        verdict = check_command(graph, command)
        verdicts.append(verdict)
        if not verdict.ok or cmd is None:
            break
        graph = transition(graph, cmd)
    return Replay(tuple(verdicts), graph)
