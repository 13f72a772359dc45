"""Scene graphs as pictures: a self-contained SVG drawing (no graphviz or plotting library needed).

Layout follows the support hierarchy, which is how people read a tabletop scene: what rests on or in
something is drawn above it, one row per support depth (the table at the bottom); articulated parts are
drawn inside their parent's box. Support edges (``on``/``in``) are solid arrows, other relations dashed.
States (open/closed/on/off/held) are shown under the node's name; nodes listed in ``highlight`` (e.g. the
objects a plan moved) are outlined in colour.
"""

from __future__ import annotations

from collections.abc import Iterable
from html import escape

from gsr.scene_graph import SceneGraph

_SUPPORT = ("on", "in")
_BOX_W, _BOX_H, _PART_H = 150, 46, 20
_GAP_X, _GAP_Y, _MARGIN = 24, 70, 20
_FILL = {
    "red": "#f4b4b4",
    "blue": "#b4c8f4",
    "green": "#b8e6b8",
    "yellow": "#f6eaa0",
    "black": "#9a9a9a",
    "white": "#ffffff",
    "orange": "#f8cf9c",
    "purple": "#d6b8ec",
    "pink": "#f6c6de",
    "brown": "#d2b48c",
    "grey": "#d0d0d0",
}


def _depths(graph: SceneGraph) -> dict[str, int]:
    """Support depth of every top-level node: 0 for unsupported nodes, 1 + its support's depth otherwise."""
    parent_of = {n.id: n.parent for n in graph.nodes}
    top = {n.id for n in graph.nodes if n.parent is None}

    def owner(node_id: str) -> str:
        seen = set()
        while parent_of.get(node_id) is not None and node_id not in seen:
            seen.add(node_id)
            node_id = parent_of[node_id]  # type: ignore[assignment]
        return node_id

    support = {}
    for e in graph.edges:
        if e.relation in _SUPPORT and e.source in top:
            support[e.source] = owner(e.target)
    depth: dict[str, int] = {}

    def depth_of(node_id: str, trail: frozenset[str] = frozenset()) -> int:
        if node_id in depth:
            return depth[node_id]
        below = support.get(node_id)
        d = (
            0
            if below is None or below in trail or below == node_id
            else depth_of(below, trail | {node_id}) + 1
        )
        depth[node_id] = d
        return d

    for node_id in top:
        depth_of(node_id)
    return depth


def scene_graph_svg(graph: SceneGraph, title: str = "", highlight: Iterable[str] = ()) -> str:
    """The graph drawn as an SVG document (a string)."""
    marked = set(highlight)
    nodes = {n.id: n for n in graph.nodes}
    parts: dict[str, list[str]] = {}
    for n in graph.nodes:
        if n.parent is not None:
            parts.setdefault(n.parent, []).append(n.id)
    depth = _depths(graph)
    rows: dict[int, list[str]] = {}
    for node_id in sorted(depth, key=lambda i: (depth[i], i)):
        rows.setdefault(depth[node_id], []).append(node_id)
    n_rows = max(rows, default=0) + 1
    heights = {i: _BOX_H + _PART_H * len(parts.get(i, [])) for i in depth}
    row_h = {r: max(heights[i] for i in ids) for r, ids in rows.items()}
    width = max((len(ids) for ids in rows.values()), default=1) * (_BOX_W + _GAP_X) + 2 * _MARGIN
    title_h = 30 if title else 0
    height = title_h + sum(row_h.values()) + _GAP_Y * (n_rows - 1) + 2 * _MARGIN

    pos: dict[str, tuple[float, float, float, float]] = {}  # id -> x, y, w, h
    y = height - _MARGIN
    for r in range(n_rows):
        ids = rows.get(r, [])
        y -= row_h.get(r, 0)
        total = len(ids) * _BOX_W + (len(ids) - 1) * _GAP_X
        x = (width - total) / 2
        for node_id in ids:
            h = heights[node_id]
            pos[node_id] = (x, y + row_h[r] - h, _BOX_W, h)
            for k, part in enumerate(parts.get(node_id, [])):
                pos[part] = (x + 6, y + row_h[r] - h + _BOX_H - 8 + k * _PART_H, _BOX_W - 12, _PART_H - 3)
            x += _BOX_W + _GAP_X
        y -= _GAP_Y

    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
        f'viewBox="0 0 {width:.0f} {height:.0f}" font-family="Helvetica, Arial, sans-serif">',
        "<defs><marker id='arrow' viewBox='0 0 10 10' refX='9' refY='5' markerWidth='7' markerHeight='7' "
        "orient='auto-start-reverse'><path d='M 0 0 L 10 5 L 0 10 z' fill='#444'/></marker></defs>",
        f'<rect width="100%" height="100%" fill="#fbfbf8"/><title>{escape(title or "scene graph")}</title>',
    ]
    if title:
        out.append(
            f'<text x="{_MARGIN}" y="{_MARGIN + 8}" font-size="15" font-weight="bold">{escape(title)}</text>'
        )
    for e in graph.edges:  # edges first, boxes on top
        if e.source not in pos or e.target not in pos:
            continue
        sx, sy, sw, sh = pos[e.source]
        tx, ty, tw, th = pos[e.target]
        support = e.relation in _SUPPORT
        x1, y1 = sx + sw / 2, sy + sh  # from the bottom of what is supported ...
        x2, y2 = tx + tw / 2, ty if support else ty + th / 2  # ... to the top of its support
        dash = "" if support else ' stroke-dasharray="4 3"'
        out.append(
            f'<line x1="{x1:.1f}" y1="{y1:.1f}" x2="{x2:.1f}" y2="{y2:.1f}" stroke="#444" stroke-width="1.3"'
            f'{dash} marker-end="url(#arrow)"/>'
        )
        out.append(
            f'<text x="{(x1 + x2) / 2 + 4:.1f}" y="{(y1 + y2) / 2:.1f}" font-size="10" fill="#333">'
            f"{escape(e.relation)}</text>"
        )
    for node_id, (x, y0, w, h) in pos.items():
        node = nodes[node_id]
        is_part = node.parent is not None
        fill = _FILL.get(node.color or "", "#eef2f7" if not is_part else "#ffffff")
        stroke, sw = ("#d0632a", 3) if node_id in marked else ("#555", 1)
        out.append(
            f'<rect x="{x:.1f}" y="{y0:.1f}" width="{w:.1f}" height="{h:.1f}" rx="6" fill="{fill}" '
            f'stroke="{stroke}" stroke-width="{sw}"/>'
        )
        label = node_id.split("/")[-1] if is_part else node_id
        states = ", ".join(node.states)
        if is_part:
            text = f"{label} [{states}]" if states else label
            out.append(f'<text x="{x + 6:.1f}" y="{y0 + 13:.1f}" font-size="11">{escape(text)}</text>')
        else:
            out.append(
                f'<text x="{x + 8:.1f}" y="{y0 + 18:.1f}" font-size="13" font-weight="bold">{escape(label)}</text>'
            )
            sub = node.category + (f" [{states}]" if states else "")
            out.append(
                f'<text x="{x + 8:.1f}" y="{y0 + 33:.1f}" font-size="11" fill="#333">{escape(sub)}</text>'
            )
    out.append("</svg>")
    return "\n".join(out)
