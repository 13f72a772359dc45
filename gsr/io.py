"""Loading user files by kind: PDDL, BDDL (LIBERO / BEHAVIOR) and scene graphs, with clear errors."""

from __future__ import annotations

import json
import os
import re
import tempfile
from pathlib import Path

from gsr.errors import GSRError
from gsr.gsr_bench_format import graph_from_gsr_bench
from gsr.libero import libero_task
from gsr.pddl.bddl import parse_bddl, parse_bddl_domain
from gsr.pddl.files import find_domain_file
from gsr.pddl.model import Domain, Problem
from gsr.pddl.parser import parse_domain, parse_pddl, parse_problem
from gsr.pddl.writer import write_domain, write_problem
from gsr.resources import load_builtin_domain
from gsr.scene_graph import SceneGraph


def write_bytes_atomic(path: str | Path, data: bytes, fsync: bool = False) -> None:
    """Write ``data`` via a temporary file in the same folder and an atomic rename: readers see the old
    file or the new one, never half of it. ``fsync`` also flushes to disk first (crash-safe resumes)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            if fsync:
                fh.flush()
                os.fsync(fh.fileno())
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the file the usual permissions
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_text_atomic(path: str | Path, text: str) -> None:
    """Write UTF-8 ``text`` atomically (see :func:`write_bytes_atomic`)."""
    write_bytes_atomic(path, text.encode("utf-8"))


def read_text(path: str | Path) -> str:
    """A file's text; GSRError naming the file when it is missing, unreadable or empty."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise GSRError(f"{p}: no such file") from None
    except IsADirectoryError:
        raise GSRError(f"{p}: is a directory, expected a file") from None
    except UnicodeDecodeError:
        raise GSRError(f"{p}: not a UTF-8 text file") from None
    except OSError as exc:
        raise GSRError(f"{p}: cannot read: {exc.strerror}") from None
    if not text.strip():
        raise GSRError(f"{p}: file is empty")
    return text


_DEFINES_DOMAIN = re.compile(r"^\s*\(\s*define\s*\(\s*domain\b", re.IGNORECASE)
_DEFINES_DOMAIN_ANYWHERE = re.compile(r"\(\s*define\s*\(\s*domain\b", re.IGNORECASE)
_COMMENT = re.compile(r";[^\n]*")


def _is_bddl(path: Path, text: str) -> bool:
    lowered = text.lower()
    return path.suffix.lower() == ".bddl" or ":obj_of_interest" in lowered or ":fixtures" in lowered


def load_any(path: str | Path) -> Domain | Problem:
    """Parse a PDDL or BDDL file into a Domain or Problem (BDDL problems keep their own predicates)."""
    p = Path(path)
    text = read_text(p)
    if not _is_bddl(p, text):
        return parse_pddl(text, str(p))
    if _DEFINES_DOMAIN.search(re.sub(r";[^\n]*", "", text)):
        return parse_bddl_domain(text, str(p))
    bddl = parse_bddl(text, str(p))
    if bddl.domain_name == "robosuite" or bddl.fixtures or bddl.regions:
        return libero_task(bddl)[1]
    return Problem(
        name=bddl.name,
        domain_name=bddl.domain_name,
        objects=dict(bddl.objects),
        init=frozenset(bddl.init),
        goal=bddl.goal,
    )


def write_any(model: Domain | Problem) -> str:
    """Normalized PDDL text of a domain or problem."""
    return write_domain(model) if isinstance(model, Domain) else write_problem(model)


def load_domain_and_problem(
    domain_file: str | Path | None, problem_file: str | Path
) -> tuple[Domain, Problem]:
    """Load a (domain, problem) pair; a LIBERO BDDL problem without a domain uses the tabletop domain."""
    problem_path = Path(problem_file)
    text = read_text(problem_path)
    if _is_bddl(problem_path, text):
        bddl = parse_bddl(text, str(problem_path))
        if domain_file is None:
            return _builtin_domain(), libero_task(bddl)[1]
        domain = load_any(domain_file)
        if not isinstance(domain, Domain):
            raise GSRError(f"{domain_file}: expected a domain, found a problem")
        problem = load_any(problem_path)
        assert isinstance(problem, Problem)
        return domain, problem
    if domain_file is None:
        if _DEFINES_DOMAIN_ANYWHERE.search(_COMMENT.sub("", text)):
            raise GSRError(f"{problem_path}: this is a domain file; give DOMAIN PROBLEM")

        # As `gsr plan` and Fast Downward's driver: domain.pddl, NAME-domain.pddl, ... beside it.
        domain_file = find_domain_file(problem_path)
        if domain_file is None:
            raise GSRError(
                f"{problem_path}: a PDDL problem needs its DOMAIN file (none beside it: domain.pddl, "
                f"{problem_path.stem}-domain.pddl, domain_{problem_path.name}, ...)"
            )
    domain = parse_domain(read_text(domain_file), str(domain_file))
    return domain, parse_problem(text, str(problem_path), domain=domain)


def _builtin_domain() -> Domain:
    return load_builtin_domain("tabletop")


def load_scene(path: str | Path) -> SceneGraph:
    """A scene graph from scene-graph JSON, a GSR-Bench message ``{nodes, edges}``, or a LIBERO BDDL file."""
    p = Path(path)
    text = read_text(p)
    if _is_bddl(p, text):
        return libero_task(parse_bddl(text, str(p)))[0]
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise GSRError(f"{p}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}") from None
    return scene_from_data(data, str(p))


def scene_from_data(data: object, source: str = "<scene>") -> SceneGraph:
    """A scene graph from parsed JSON: scene-graph JSON or a GSR-Bench message ``{nodes: [str], edges: [str]}``."""
    if isinstance(data, dict) and data.get("nodes") and all(isinstance(n, str) for n in data["nodes"]):
        return graph_from_gsr_bench(data)
    return SceneGraph.from_data(data, source)
