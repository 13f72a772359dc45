"""Where GSR's shipped data lives (domain files, catalog) and cached access to the built-in domains."""

from __future__ import annotations

import os
import sys
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

from gsr.errors import GSRError
from gsr.pddl.parser import load_domain

if TYPE_CHECKING:
    from gsr.pddl.model import Domain

_PACKAGE_DIR = Path(__file__).resolve().parent


def _candidates() -> list[Path]:
    """Data folders in priority order: $GSR_DATA, the checkout's data/, installed copies."""
    out: list[Path] = []
    env = os.environ.get("GSR_DATA")
    if env:
        out.append(Path(env).expanduser())
    out.append(_PACKAGE_DIR.parent / "data")  # source checkout: repo/gsr and repo/data side by side
    out.append(_PACKAGE_DIR / "data")  # package data, if a build copies it into the package
    out.append(Path(sys.prefix) / "share" / "gsr" / "data")  # setuptools data-files install
    return out


def data_dir() -> Path:
    """The data folder: env ``GSR_DATA``, else the repository's ``data/``, else installed package data."""
    env = os.environ.get("GSR_DATA")
    if env:
        p = Path(env).expanduser()
        if not p.is_dir():
            raise GSRError(f"GSR_DATA={env}: not a directory")
        return p
    for p in _candidates():
        if (p / "domains").is_dir():
            return p
    tried = ", ".join(str(p) for p in _candidates())
    raise GSRError(f"GSR data folder not found (tried {tried}); set GSR_DATA")


def shared_data_dir() -> Path:
    """Third-party reference data (LIBERO, IPC PDDL, BEHAVIOR, GSR-Bench): ``$GSR_SHARED_DATA``, else
    ``../shared/data`` beside the checkout."""
    env = os.environ.get("GSR_SHARED_DATA")
    return Path(env).expanduser() if env else _PACKAGE_DIR.parents[1] / "shared" / "data"


def cache_dir() -> Path:
    """Where ``gsr data fetch`` keeps fetched reference sets: ``$GSR_CACHE``, else the user cache folder
    (``$XDG_CACHE_HOME/gsr`` or ``~/.cache/gsr``; ``~/Library/Caches/gsr`` on macOS, ``%LOCALAPPDATA%\\gsr``
    on Windows). Separate from ``$GSR_DATA``, the project's own data folder (domains, catalog)."""
    env = os.environ.get("GSR_CACHE")
    if env:
        return Path(env).expanduser()
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Caches" / "gsr"
    if sys.platform == "win32" and os.environ.get("LOCALAPPDATA"):
        return Path(os.environ["LOCALAPPDATA"]) / "gsr"
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg).expanduser() if xdg else Path.home() / ".cache") / "gsr"


def domain_path(name: str = "tabletop") -> Path:
    """The path of a built-in domain file ``data/domains/<name>.pddl``."""
    path = data_dir() / "domains" / f"{name}.pddl"
    if not path.is_file():
        known = sorted(p.stem for p in (data_dir() / "domains").glob("*.pddl"))
        raise GSRError(f"no built-in domain {name!r} (known: {', '.join(known) or 'none'})")
    return path


@lru_cache(maxsize=8)
def _load(path: str, mtime: float) -> Domain:
    return load_domain(path)


def load_builtin_domain(name: str = "tabletop") -> Domain:
    """The parsed built-in domain ``name`` (cached; reloaded when the file changes)."""
    path = domain_path(name)
    return _load(str(path), path.stat().st_mtime)
