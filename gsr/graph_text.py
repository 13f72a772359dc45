"""Compact, deterministic prompt text for a scene graph (token-frugal, for language models).

Example::

    objects: table (table); blue_box (box, blue); red_cube1 (cube, red); short_cabinet (cabinet)
      parts: drawer_low [closed], drawer_middle [open]
    relations: blue_box on table; red_cube1 in blue_box

Categories are omitted where the name already says them only when ``terse=True``; node order and
edge order follow the graph, so the same graph always gives the same text.
"""

from __future__ import annotations

from gsr.scene_graph import Node, SceneGraph

#: Attributes worth a token in a prompt (in this order); poses, boxes and keypoints are left out.
PROMPT_ATTRIBUTES: tuple[str, ...] = ("color", "secondary_color", "material", "size")


def _part_name(node: Node) -> str:
    prefix = f"{node.parent}/"
    return node.id[len(prefix) :] if node.parent and node.id.startswith(prefix) else node.id


def _details(node: Node, terse: bool) -> str:
    bits: list[str] = []
    if not (terse and node.category in _part_name(node)):
        bits.append(node.category)
    bits.extend(str(node.attributes[k]) for k in PROMPT_ATTRIBUTES if k in node.attributes)
    return f" ({', '.join(bits)})" if bits else ""


def _states(node: Node) -> str:
    return f" [{', '.join(node.states)}]" if node.states else ""


def node_text(node: Node, terse: bool = False) -> str:
    """``red_cube1 (cube, red)`` / ``drawer_low [closed]`` for one node."""
    name = _part_name(node) if node.parent else node.id
    return f"{name}{_details(node, terse)}{_states(node)}"


def to_prompt_text(graph: SceneGraph, terse: bool = False) -> str:
    """The graph as two compact lines of text: objects (with their parts) and relations."""
    children: dict[str, list[Node]] = {}
    for n in graph.nodes:
        if n.parent is not None:
            children.setdefault(n.parent, []).append(n)
    entries: list[str] = []
    for n in graph.nodes:
        if n.parent is not None:
            continue
        text = node_text(n, terse)
        parts = children.get(n.id)
        if parts:
            text += " parts: " + ", ".join(_part_entry(p, children, terse) for p in parts)
        entries.append(text)
    relations = [f"{e.source} {e.relation.replace('_', ' ')} {e.target}" for e in graph.edges]
    lines = [f"objects: {'; '.join(entries) if entries else '(none)'}"]
    lines.append(f"relations: {'; '.join(relations) if relations else '(none)'}")
    return "\n".join(lines)


def _part_entry(node: Node, children: dict[str, list[Node]], terse: bool) -> str:
    text = node_text(node, terse)
    sub = children.get(node.id)
    if sub:  # parts of parts (a drawer's handle): nested in braces
        text += " {" + ", ".join(_part_entry(p, children, terse) for p in sub) + "}"
    return text
