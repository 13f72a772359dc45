"""The ``in`` errors dev tool's command line (the scoring itself is tested on synthetic graphs elsewhere)."""

from __future__ import annotations

from gsr.benchmarks.perception.in_errors import main


def test_first_must_name_a_scene_of_the_stream(capsys):
    assert main(["--scenes", "3", "--first", "5"]) == 1
    err = capsys.readouterr().err.strip()
    assert err == "error: --first 5 must lie in 0 .. 2 (--scenes 3)"
    assert main(["--scenes", "3", "--first", "-1"]) == 1
