"""The datagen measurement: rows of a small generated dataset, classified against their reference goals."""

from __future__ import annotations

from pathlib import Path

from gsr.language.measure import KINDS, classify, generated_rows, main, measure
from gsr.pddl.parser import parse_formula
from tests.gsr.language.test_constructions import kitchen


def test_generated_rows_are_classified() -> None:
    report = measure(generated_rows(600, seed=3), examples=2)
    assert report["rows"] > 40
    assert sum(report["counts"].values()) == report["rows"]
    assert set(report["counts"]) == set(KINDS)
    # the grounder recovers most of the generator's goals (97% on 14000 rows, docs/language.md)
    assert report["counts"]["equivalent"] >= 0.85 * report["rows"]
    assert report["counts"]["unknown_word"] == 0


def test_classify_kinds() -> None:
    g = kitchen()
    ref = parse_formula("(and (in orange_orange_6 green_crate_4))")
    assert classify("put the orange in the crate", g, ref) == ("equivalent", "")
    kind, got = classify("put the orange in the box", g, ref)
    assert kind == "wrong_goal" and "blue_box_6" in got
    assert classify("frobnicate the orange", g, ref) == ("unknown_word", "frobnicate")
    assert classify("put the orange in the glass cup", g, ref)[0] == "ambiguous"


def test_bad_data_directory_exits_1(tmp_path: Path, capsys) -> None:
    assert main(["--data", str(tmp_path)]) == 1
    assert "not a gsr datagen output directory" in capsys.readouterr().err
