"""Every third-party module the installed packages import is declared in pyproject.toml (base or an extra).

A missing declaration passes every test in a full development venv and fails only on a user's machine
(e.g. scipy imported by perception but declared nowhere broke a bare clone's `make demo`)."""

from __future__ import annotations

import ast
import re
import sys
import tomllib
from importlib.metadata import packages_distributions
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE_DIRS = ("gsr", "perception", "skills", "benchmarks")


def _norm(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _declared() -> dict[str, str]:
    """Distribution name -> where it is declared ('base' or the extra's name)."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    out = {}
    groups = {"base": project["dependencies"], **project.get("optional-dependencies", {})}
    for group, reqs in groups.items():
        for req in reqs:
            out.setdefault(_norm(re.match(r"[A-Za-z0-9_.\-]+", req).group(0)), group)
    return out


def _imported_modules() -> dict[str, str]:
    """Top-level third-party module -> one file importing it."""
    local = {"gsr", "tests", *PACKAGE_DIRS}
    found: dict[str, str] = {}
    for folder in PACKAGE_DIRS:
        for path in sorted((ROOT / folder).rglob("*.py")):
            tree = ast.parse(path.read_text(), filename=str(path))
            for node in ast.walk(tree):
                if isinstance(node, ast.Import):
                    names = [a.name for a in node.names]
                elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                    names = [node.module]
                else:
                    continue
                for name in names:
                    top = name.split(".")[0]
                    if top not in local and top not in sys.stdlib_module_names:
                        found.setdefault(top, str(path.relative_to(ROOT)))
    return found


def test_every_imported_third_party_module_is_declared() -> None:
    declared = _declared()
    dists = packages_distributions()
    undeclared = []
    for module, where in sorted(_imported_modules().items()):
        names = {_norm(d) for d in dists.get(module, [])}
        if not names and _norm(module) in declared:
            continue  # an extra not installed in this venv, declared under the module's own name
        if not names:
            undeclared.append(f"{module} (imported by {where}; not installed here, so no distribution known)")
        elif not names & declared.keys():
            undeclared.append(
                f"{module} (imported by {where}; distribution {sorted(names)} not in pyproject)"
            )
    assert not undeclared, "undeclared third-party imports:\n" + "\n".join(undeclared)
