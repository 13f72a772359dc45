"""LIBERO reasoning cases shared by the measurement (:mod:`gsr.reason.measure`) and the tiny model's
training (:mod:`gsr.reason.tiny_model`): the cases of a folder, the fixed even/odd split between them,
and the compact prompt options both use."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from gsr.errors import GSRError
from gsr.libero import libero_task
from gsr.pddl.bddl import parse_bddl

#: Prompt options shared by the training pairs and the measurement runs.
PROMPT_OPTIONS = {"examples": (), "prompt_actions": "signatures"}


def split_cases(cases: list, split: str) -> list:
    """``all`` cases, or the ``even`` / ``odd`` positions of the sorted list (a fixed train/test split)."""
    if split == "all":
        return cases
    if split not in ("even", "odd"):
        raise GSRError(f"unknown split {split!r}: all, even or odd")
    return cases[split == "odd" :: 2]


def libero_cases(folder: Path) -> list[tuple[str, Any, Any, str]]:
    """(name, graph, benchmark goal formula, instruction) for every ``*.bddl`` under ``folder``, sorted."""
    cases = []
    for path in sorted(folder.rglob("*.bddl")):
        bddl = parse_bddl(path.read_text(encoding="utf-8"), str(path))
        graph, problem = libero_task(bddl)
        cases.append((f"{path.parent.name}/{path.stem}", graph, problem.goal, bddl.language or ""))
    return cases
