"""benchmarks/perception/cpu_profile.py: CPU profile of perceive on rendered scenes."""

import pytest
from gsr.benchmarks.perception.cpu_profile import main


def test_bad_counts_are_one_line_errors(capsys):
    assert main(["--scenes", "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--scenes" in err


@pytest.mark.physics
def test_profile_names_the_pipeline_and_a_cpu_rate(capsys):
    pytest.importorskip("pybullet")
    assert main(["--scenes", "1", "--cameras", "1", "--top", "5"]) == 0
    out = capsys.readouterr().out
    assert "frames per CPU-second" in out
    assert "pipeline.py" in out and "(perceive)" in out  # the project's functions, by cumulative CPU
