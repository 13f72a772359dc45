"""``gsr data fetch|list|path``: the command side of :mod:`gsr.data_sets`."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from gsr.data_sets import SETS, copies, count_files, fetch, fetch_names, fetched_dir, locate
from gsr.resources import cache_dir


def _bar(label: str):
    """A progress callback drawing a bar on stderr (a terminal), or nothing (logs)."""
    if not sys.stderr.isatty():
        return None, lambda: None
    state = {"shown": -1}

    def progress(done: int, total: int) -> None:
        if total <= 0:
            return
        pct = min(100, done * 100 // total)
        if pct != state["shown"]:
            state["shown"] = pct
            filled = pct * 30 // 100
            sys.stderr.write(
                f"\r{label} [{'#' * filled}{'.' * (30 - filled)}] {pct:3d}% of {total / 1e6:.1f} MB"
            )
            sys.stderr.flush()

    def close() -> None:
        if state["shown"] >= 0:
            sys.stderr.write("\n")
            sys.stderr.flush()

    return progress, close


def fetch_command(names: list[str], cache: Path | None, force: bool) -> None:
    """Fetch every named set (all names checked first); one line per set."""
    root = cache or cache_dir()
    for ds in fetch_names(names):
        progress, close = _bar(f"{ds.name}: {ds.filename}")
        try:
            got = fetch(ds.name, root, force=force, progress=progress)
        finally:
            close()
        verb = "already present" if got.already else f"fetched {ds.package}=={ds.version} (sha256 ok)"
        typer.echo(f"{got.name}: {verb}: {got.files} files in {got.path}")


def list_text(cache: Path | None = None) -> str:
    """Every known set: where each copy is, or how to get it."""
    root = cache or cache_dir()
    lines = [f"cache: {root} (GSR_CACHE)"]
    for name, ds in SETS.items():
        lines.append(f"{name}: {ds.description}; licence: {ds.licence}")
        found = copies(name, root)
        for c in found:
            lines.append(f"  {c.kind:9s} {count_files(c.path):5d} files  {c.path}")
        if ds.fetchable and not any(c.kind == "fetched" for c in found):
            lines.append(f"  fetch:    gsr data fetch {name}  (into {fetched_dir(name, root)})")
        if not ds.fetchable and not found:
            lines.append(f"  provide:  {ds.provide}")
    return "\n".join(lines)


def path_command(name: str, cache: Path | None) -> None:
    """Print the best copy's folder (for ``--source "$(gsr data path libero)"``)."""
    typer.echo(str(locate(name, cache)))
