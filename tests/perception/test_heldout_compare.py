"""The held-out comparison of weight folders (``python -m gsr.benchmarks.perception.train_data``)."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

from gsr.benchmarks.perception.train_data import compare_heldout, main


def test_a_folder_without_weights_is_one_line_and_exit_1(tmp_path, capsys) -> None:
    assert main([str(tmp_path)]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and "\n" not in err and "model.npz" in err


@pytest.mark.slow
def test_weights_are_scored_on_the_same_frames() -> None:
    report = compare_heldout(["shipped", "rules"], seed=0, scenes=1)
    shipped, rules = report["shipped"], report["rules"]
    assert shipped["frames"] == rules["frames"] == 4
    assert shipped["truth_objects"] == rules["truth_objects"] > 0
    # the trained models buy precision and category accuracy over the rules (the card's finding)
    assert shipped["precision"] > rules["precision"]
    assert shipped["category_accuracy"] > rules["category_accuracy"]
