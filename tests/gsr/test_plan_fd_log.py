"""What the FD wrapper reads from Fast Downward's log (translator_stats), with and without FD."""

from __future__ import annotations

import pytest

from gsr.plan.fast_downward import find_fast_downward, run_fast_downward, translator_stats
from tests.data_paths import PDDL

LOG = """INFO     Running translator.
Parsing... [0.010s CPU, 0.011s wall-clock]
Translating task: [0.020s CPU, 0.006s wall-clock]
Translator operators: 32
Translator axioms: 3
Done! [0.030s CPU, 0.094s wall-clock]
translate exit code: 0
INFO     Running search (release).
"""


def test_translator_stats_from_a_finished_translation() -> None:
    stats = translator_stats(LOG)
    assert stats == {
        "translated": True,
        "translate_cpu": 0.03,
        "translate_wall": 0.094,
        "operators": 32,
        "axioms": 3,
    }


def test_translator_stats_of_a_translation_cut_short() -> None:
    cut = LOG.split("Translator operators")[0]  # killed while translating: no summary, no exit code
    assert translator_stats(cut) == {"translated": False}
    assert translator_stats("") == {"translated": False}


def test_details_and_cpu_limit_reach_fast_downward() -> None:
    if find_fast_downward() is None:
        pytest.skip("Fast Downward (up-fast-downward) is not installed")
    details: dict = {}
    status, plan, message = run_fast_downward(
        PDDL / "blocks" / "domain.pddl",
        PDDL / "blocks" / "probBLOCKS-4-0.pddl",
        120,
        details=details,
        cpu_limit=60,
    )
    assert status == "solved", message
    assert plan is not None and len(plan) > 0
    assert details["translated"] is True and details["operators"] > 0 and details["translate_wall"] >= 0
