"""The import contract: the one-way layering benchmarks -> skills -> perception -> gsr (core).

Every import in the four packages is read from the source (module level, inside functions and under
``TYPE_CHECKING`` alike, plus string module names given to ``importlib.import_module`` or kept in lazy
export tables), and none may name a package of a higher layer. A layer may use any layer below it.
Command-line sub-apps of the upper layers reach the ``gsr`` command through entry points
(``[project.entry-points."gsr.cli"]``), so the core never names them.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

#: Lowest layer first; a package may import its own layer and those before it.
LAYERS = ("gsr", "perception", "skills", "benchmarks")
#: Each layer's import name: the upper layers' folders install under the ``gsr`` namespace
#: (``skills/`` is ``gsr.skills``), so no generic top-level name reaches a user's environment.
IMPORT_NAMES = {
    "gsr": "gsr",
    "perception": "gsr.perception",
    "skills": "gsr.skills",
    "benchmarks": "gsr.benchmarks",
}


def _rank(module: str) -> int | None:
    best = None
    for rank, layer in enumerate(LAYERS):
        name = IMPORT_NAMES[layer]
        if module == name or module.startswith(name + "."):
            best = rank  # the longest (most specific) name wins: gsr.skills over gsr
    return best


def _imports(path: Path) -> list[tuple[int, str]]:
    """(line, module) for every import statement and string module reference in a file."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    out: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            out.append((node.lineno, node.module))
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            # "gsr.skills.camera"-style strings: lazy export tables and import_module arguments
            text = node.value
            if (
                text.count(".") >= 1
                and _rank(text) is not None
                and text.replace(".", "").replace("_", "").isalnum()
            ):
                out.append((node.lineno, text))
    return out


def _violations() -> list[str]:
    found = []
    for layer_rank, layer in enumerate(LAYERS):
        for path in sorted((REPO / layer).rglob("*.py")):
            for line, module in _imports(path):
                rank = _rank(module)
                if rank is not None and rank > layer_rank:
                    found.append(
                        f"{path.relative_to(REPO)}:{line}: {layer} imports {module} (layer {LAYERS[rank]})"
                    )
    return found


def test_no_upward_imports() -> None:
    problems = _violations()
    assert not problems, "upward imports break the layering:\n" + "\n".join(problems)


@pytest.mark.parametrize(
    ("source", "bad"),
    [
        ("from gsr.benchmarks.demo import run_demo\n", True),
        ("def f():\n    import gsr.skills.camera\n", True),
        ("LAZY = {'CameraSpec': 'gsr.skills.camera'}\n", True),
        ("from gsr.scene_graph import SceneGraph\n", False),
        ("HELP = 'see skills. for more'\n", False),
        ("from skills.camera import CameraSpec\n", False),
    ],
)
def test_the_checker_sees_every_kind_of_import(tmp_path: Path, source: str, bad: bool) -> None:
    f = tmp_path / "m.py"
    f.write_text(source)
    assert any(_rank(m) and _rank(m) > 0 for _, m in _imports(f)) is bad


def test_no_private_name_crosses_a_module() -> None:
    """``from a.b import _x`` couples two modules through a name that promises nothing: make it public."""
    problems = []
    for layer in LAYERS:
        for path in sorted((REPO / layer).rglob("*.py")):
            tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
            for node in ast.walk(tree):
                if (
                    isinstance(node, ast.ImportFrom)
                    and node.level == 0
                    and _rank(node.module or "") is not None
                ):
                    problems += [
                        f"{path.relative_to(REPO)}:{node.lineno}: from {node.module} import {a.name}"
                        for a in node.names
                        if a.name.startswith("_") and not a.name.startswith("__")
                    ]
    assert not problems, "private names imported across modules:\n" + "\n".join(problems)


def test_no_generic_top_level_import_names() -> None:
    """The upper layers are ``gsr.perception``, ``gsr.skills`` and ``gsr.benchmarks`` (setup.py maps the
    folders); importing the bare folder names would load a second copy of each module."""
    generic = {"perception", "skills", "benchmarks"}
    problems = []
    for path in sorted(p for d in (*LAYERS, "tests") for p in (REPO / d).rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in ast.walk(tree):
            names = (
                [a.name for a in node.names]
                if isinstance(node, ast.Import)
                else [node.module]
                if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module
                else []
            )
            problems += [
                f"{path.relative_to(REPO)}:{node.lineno}: import {n}"
                for n in names
                if n.split(".")[0] in generic
            ]
    assert not problems, "import the layers as gsr.<layer>:\n" + "\n".join(problems)


def test_setup_maps_every_layer_folder_under_gsr() -> None:
    text = (REPO / "setup.py").read_text(encoding="utf-8")
    for layer in LAYERS[1:]:
        assert f'"{IMPORT_NAMES[layer]}": "{layer}"' in text
