"""The episode seams live in the core (gsr.episode) and every layer's implementation satisfies them."""

from __future__ import annotations

import sys
import types

import pytest

from gsr.episode import OUTCOMES, Agent, EpisodeResult, Executor
from gsr.errors import GSRError


def test_the_runner_and_its_executors_use_the_core_seams() -> None:
    from gsr.benchmarks import agents, runner
    from gsr.benchmarks.gsr_bench_executor import GSRBenchExecutor

    from gsr.symbolic_executor import SymbolicExecutor

    # one definition: the upper layer names the core's types, it does not redefine them
    assert runner.Executor is Executor and runner.EpisodeResult is EpisodeResult and agents.Agent is Agent
    for executor in (SymbolicExecutor(), GSRBenchExecutor()):
        assert isinstance(executor, Executor), type(executor).__name__


def test_simulator_executors_are_executors() -> None:
    pytest.importorskip("pybullet", reason="the simulator executors need pybullet")
    from gsr.skills.perceived_executor import RunnerSimExecutor
    from gsr.skills.sim_executor import SimExecutor

    # constructing one builds no world (that happens in reset), so the check is cheap
    assert isinstance(SimExecutor(seed=0, frame_camera=None), Executor)
    assert isinstance(RunnerSimExecutor(seed=0), Executor)


def test_builtin_agents_are_agents_and_a_partial_one_is_refused() -> None:
    from gsr.benchmarks.agents import BUILTIN, make_agent

    for name in BUILTIN:
        agent = make_agent(name)
        assert isinstance(agent, Agent), name
        assert agent.name

    class NoAct:
        name = "no-act"

        def reset(self, task, domain, seed) -> None:
            pass

    assert not isinstance(NoAct(), Agent)
    module = types.ModuleType("_gsr_seam_probe")
    module.NoAct = NoAct  # type: ignore[attr-defined]
    sys.modules[module.__name__] = module
    try:
        with pytest.raises(GSRError, match="lacks reset"):
            make_agent("_gsr_seam_probe:NoAct")
    finally:
        del sys.modules[module.__name__]


def test_episode_result_record() -> None:
    result = EpisodeResult(
        id="t",
        suite="s",
        category="c",
        level=None,
        trial=0,
        seed=1,
        success=False,
        score=0.5,
        recall=0.5,
        steps=2,
        proposed=3,
        valid=2,
        outcome="planning_error",
        reason="step 3 rejected",
        time=0.1,
    )
    row = result.to_dict()
    assert row["executability"] == pytest.approx(2 / 3, abs=1e-6)
    assert row["outcome"] in OUTCOMES and row["plan"] == [] and row["frames"] == []
    empty = EpisodeResult(**{k: v for k, v in row.items() if k != "executability"} | {"proposed": 0})
    assert empty.executability == 1.0
