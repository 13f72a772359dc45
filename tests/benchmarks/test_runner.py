"""The runner: checked steps, outcome classes, retries with feedback, step limit, workers, Ray, reports."""

from __future__ import annotations

import json
import sys

import pytest
from gsr.benchmarks.agents import make_agent
from gsr.benchmarks.report import results_document, write_reports
from gsr.benchmarks.runner import RunConfig, run_episode, run_tasks
from gsr.benchmarks.suites.builder import SceneBuilder

from gsr.errors import GSRError
from gsr.task_spec import TaskSpec
from tests.benchmarks.scripted_agents import Scripted

AGENT = "tests.benchmarks.scripted_agents:Scripted"


@pytest.fixture()
def task() -> TaskSpec:
    b = SceneBuilder(seed=0)
    b.add("box", "lidded_box", states=("closed",))
    b.add("red_cube", "cube", color="red")
    b.add("blue_cube", "cube", color="blue")
    return TaskSpec(
        id="cube_in_box",
        suite="unit",
        category="c",
        level="Simple",
        instructions=("put the red cube in the box",),
        initial=b.graph(),
        layout=b.layout(),
        goal="(and (in red_cube box) (in blue_cube box))",
        goal_alternatives=("(and (in red_cube box) (not (open box)))",),
    )


GOOD = [["open", "box"], ["pick", "red_cube", "table"], ["place_in", "red_cube", "box"]]


def test_planner_episode_true_success(task, domain) -> None:
    r = run_episode(task, make_agent("planner"), domain)
    assert r.success and r.outcome == "true_success" and r.score == 1.0
    assert r.steps == r.proposed == r.valid and r.executability == 1.0
    assert r.plan and r.plan[0].startswith("(")


def test_invalid_step_is_a_planning_error_with_diagnosis(task, domain) -> None:
    agent = Scripted([["pick", "red_cube", "table"], ["place_in", "red_cube", "box"]])
    r = run_episode(task, agent, domain)
    assert not r.success and r.outcome == "planning_error"
    assert r.proposed == 2 and r.valid == 1 and r.executability == 0.5
    assert "rejected" in r.reason and r.failure is not None and not r.failure["ok"]


def test_retries_feed_the_diagnosis_back(task, domain) -> None:
    agent = Scripted([["place_in", "red_cube", "box"], *GOOD[1:]], retry_with=["open", "box"])
    r = run_episode(task, agent, domain, retries=1)
    assert len(agent.feedback) == 1 and not agent.feedback[0].ok
    # the rejected place_in was retried as open, then the script went on: 4 proposed, 3 valid
    assert r.proposed == 4 and r.valid == 3 and r.plan[0] == "(open box)"
    r0 = run_episode(task, Scripted([["place_in", "red_cube", "box"]], retry_with=["open", "box"]), domain)
    assert r0.outcome == "planning_error" and r0.valid == 0


class _Looping:
    """Repeats pick, a failing place_in, a recovery place_on: the failure never comes twice in a row."""

    name = "looping"

    def reset(self, task, domain, seed: int) -> None:
        self.n = 0

    def act(self, graph, instruction, feedback=None):
        from gsr.step import Step

        cycle = [
            Step("pick", ("red_cube", "table")),
            Step("place_in", ("red_cube", "box")),  # the box is closed: rejected
            Step("place_on", ("red_cube", "table")),
        ]
        self.n += 1
        return cycle[(self.n - 1) % 3]


def test_a_step_that_keeps_failing_between_recoveries_ends_the_episode(task, domain) -> None:
    r = run_episode(task, _Looping(), domain, retries=2)
    # the place_in failed three times (retries + 1), each time after a successful recovery step
    assert r.outcome == "planning_error" and "rejected" in r.reason
    assert r.proposed == 8 and r.valid == 5


def test_false_positive_and_goal_error(task, domain) -> None:
    r = run_episode(task, Scripted(GOOD), domain)
    # the open box does not satisfy the alternative; only 1 of 2 relations of the canonical goal
    assert not r.success and r.outcome == "false_positive" and r.score == 0.5
    r = run_episode(task, Scripted(GOOD, believed="(in red_cube box)"), domain)
    assert r.outcome == "goal_error"
    r = run_episode(task, Scripted([*GOOD, ["close", "box"]]), domain)
    assert r.success and r.best_alternative == 1  # the alternative holds


def test_step_limit(task, domain) -> None:
    r = run_episode(task, make_agent("random"), domain, seed=1, max_steps=1)
    assert not r.success and r.outcome == "planning_error" and "step limit" in r.reason


def test_workers_and_seed_determinism(task) -> None:
    tasks = [task, task.model_copy(update={"id": "second"})]
    config = RunConfig(agent="random", seed=5, max_steps=50)
    one = [r.to_dict() for r in run_tasks(tasks, config, trials=2)]
    two = [r.to_dict() for r in run_tasks(tasks, config, trials=2, workers=2)]
    strip = lambda rows: [{k: v for k, v in r.items() if k != "time"} for r in rows]  # noqa: E731
    assert strip(one) == strip(two)
    assert len({r["seed"] for r in one}) == 4


def test_bad_agent_and_backend(task) -> None:
    with pytest.raises(GSRError, match="unknown agent"):
        run_tasks([task], RunConfig(agent="nobody"))
    with pytest.raises(GSRError, match="cannot import"):
        make_agent("no_such_module:Agent")
    with pytest.raises(GSRError, match="unknown backend"):
        run_tasks([task], RunConfig(), backend="slurm")


def test_ray_missing_gives_a_clear_error(task, monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray -> ImportError
    with pytest.raises(GSRError, match=r"pip install 'gsr\[dist\]'"):
        run_tasks([task], RunConfig(), backend="ray")


@pytest.mark.slow
def test_ray_backend_matches_local(task) -> None:
    pytest.importorskip("ray")
    tasks = [task, task.model_copy(update={"id": "second"})]
    config = RunConfig(agent="random", seed=3, max_steps=50)
    local = [r.to_dict() for r in run_tasks(tasks, config)]
    remote = [r.to_dict() for r in run_tasks(tasks, config, backend="ray")]
    strip = lambda rows: [{k: v for k, v in r.items() if k != "time"} for r in rows]  # noqa: E731
    assert strip(local) == strip(remote)


def test_reports_are_written_atomically(task, tmp_path, monkeypatch) -> None:
    results = run_tasks([task], RunConfig(agent="planner", reference="lazy-ff"))
    doc = results_document(results, suite="unit", agent="planner", seed=0, trials=1, backend="local")
    paths = write_reports(tmp_path / "out", doc)
    data = json.loads(paths[0].read_text())
    assert {"suite", "agent", "success_rate", "tasks"} <= set(data)
    row = data["tasks"][0]
    assert {"id", "category", "level", "success", "score", "steps", "reason"} <= set(row)
    assert row["reference_steps"] == row["steps"] and data["metrics"]["length_vs_reference"] == 1.0
    assert "| c / Simple |" in paths[1].read_text()
    assert paths[2].read_text().startswith("<!doctype html>")

    # a crash while writing leaves the previous file intact and no temporary behind
    def boom(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr("gsr.io.os.replace", boom)  # the one atomic writer all reports go through
    with pytest.raises(KeyboardInterrupt):
        write_reports(tmp_path / "out", {**doc, "success_rate": 0.0})
    assert json.loads(paths[0].read_text()) == data
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "report.html",
        "report.md",
        "results.json",
    ]


def test_reasoner_agent_with_backends(task, domain) -> None:
    # the instruction names only the red cube while the task wants both: the grounder's goal is wrong
    wrong = run_episode(task, make_agent("reasoner", {"backend": "grounder"}), domain)
    assert wrong.outcome == "goal_error" and wrong.score == 0.5
    right = task.model_copy(update={"goal": "(in red_cube box)", "goal_alternatives": ()})
    ok = run_episode(right, make_agent("reasoner", {"backend": "grounder"}), domain)
    assert ok.success, ok.reason
    done = run_episode(
        task, make_agent("reasoner", {"backend": "tests.benchmarks.scripted_agents:always_done"}), domain
    )
    assert not done.success and done.outcome in ("false_positive", "planning_error")
    bad = run_episode(
        task,
        make_agent("reasoner", {"backend": "tests.benchmarks.scripted_agents:bad_step", "max_repairs": 2}),
        domain,
    )
    assert not bad.success and bad.proposed >= 3 and bad.executability < 1.0
    with pytest.raises(GSRError, match="cannot import"):
        make_agent("reasoner", {"backend": "nowhere:fn"})


def test_frames_are_saved_and_linked_from_the_reports(task, tmp_path) -> None:
    import numpy as np
    from gsr.benchmarks.runner import save_frames
    from PIL import Image

    out = tmp_path / "out"
    rgb = [np.full((24, 32, 3), k * 60, dtype=np.uint8) for k in range(3)]
    [result] = run_tasks([task], RunConfig(agent="planner"))
    result.frames = save_frames(rgb, str(out / "frames"), "libero/odd id:1", 0)
    result.perceived_success = False
    assert result.frames == [f"frames/libero_odd_id_1-t0-{k}.png" for k in range(3)]
    for k, rel in enumerate(result.frames):
        img = np.asarray(Image.open(out / rel))
        assert img.shape == (24, 32, 3) and int(img[0, 0, 0]) == k * 60  # the real frame, not a placeholder
    assert sorted(p.name for p in (out / "frames").iterdir()) == [p.split("/")[1] for p in result.frames]
    doc = results_document([result], suite="unit", agent="planner", physical=True, perceive=True)
    md_path, html_path = write_reports(out, doc)[1:]
    md, page = md_path.read_text(), html_path.read_text()
    assert "## Frames (1 episodes" in md and "(frames/libero_odd_id_1-t0-2.png)" in md
    assert 'src="frames/libero_odd_id_1-t0-0.png"' in page and "<figure>" in page
    assert "perceived" in md and "only in the world (perception missed it): 1" in md
    assert json.loads((out / "results.json").read_text())["tasks"][0]["frames"] == result.frames


def test_reports_without_frames_have_no_frame_section(task, tmp_path) -> None:
    doc = results_document(run_tasks([task], RunConfig()), suite="unit", agent="planner")
    md_path, html_path = write_reports(tmp_path, doc)[1:]
    assert "## Frames" not in md_path.read_text() and "<figure>" not in html_path.read_text()


def test_perceive_needs_physical(task) -> None:
    with pytest.raises(GSRError, match="--perceive needs --physical"):
        run_tasks([task], RunConfig(perceive=True))


@pytest.fixture()
def libero_goal_tasks(libero_dir):
    from gsr.benchmarks.suites import get_suite

    return get_suite("libero").tasks(str(libero_dir / "libero_goal"), 0)


@pytest.mark.physics
def test_physical_run_saves_first_middle_last_frames(libero_goal_tasks, tmp_path) -> None:
    pytest.importorskip("pybullet")
    from PIL import Image

    task = next(t for t in libero_goal_tasks if t.id.endswith("put_the_bowl_on_the_plate"))
    config = RunConfig(physical=True, frames_dir=str(tmp_path / "frames"))
    [result] = run_tasks([task], config)
    assert result.success, result.reason
    assert len(result.frames) == 3  # pick + place: 3 observations, all kept (first, middle, last)
    first, last = (Image.open(tmp_path / p) for p in (result.frames[0], result.frames[-1]))
    assert first.size == last.size and first.tobytes() != last.tobytes()  # the bowl moved in between
    assert not [p for p in (tmp_path / "frames").iterdir() if p.name.startswith(".")]  # no temporaries


@pytest.mark.physics
def test_physical_run_from_perception(libero_goal_tasks) -> None:
    pytest.importorskip("pybullet")
    pytest.importorskip("open3d")
    wanted = ("put_the_bowl_on_the_plate", "turn_on_the_stove", "push_the_plate_to_the_front_of_the_stove")
    tasks = [t for t in libero_goal_tasks if t.id.endswith(wanted)]
    results = run_tasks(tasks, RunConfig(physical=True, perceive=True))
    assert [r.success for r in results] == [True] * 3, [r.reason for r in results]
    # the goal also holds in what the agent perceived: the region from the map, the stove's power
    # state carried from its own turn_on (no camera shows it)
    assert all(r.perceived_success for r in results)


def test_reasoner_agent_is_closed_loop_on_the_graph_it_is_shown(task, domain) -> None:
    """A skill that reports success but leaves the world unchanged: the reasoner sees the graph and re-plans."""
    from gsr.symbolic_executor import SymbolicExecutor

    class SlippingExecutor(SymbolicExecutor):
        """The first pick 'succeeds' but the object slips: the state does not change."""

        slipped = False

        def execute(self, step):
            diagnosis = super().execute(step)
            if diagnosis.ok and step.action == "pick" and not self.slipped:
                self.slipped, self.state = True, diagnosis.transition[0]
            return diagnosis

    right = task.model_copy(update={"goal": "(in red_cube box)", "goal_alternatives": ()})
    agent = make_agent("reasoner", {"backend": "grounder"})
    result = run_episode(right, agent, domain, executor=SlippingExecutor())
    assert result.success, result.reason
    assert agent.replans == 1 and sum(s.startswith("(pick") for s in result.plan) == 2
    # the same world with a faithful executor: the plan is followed, no re-plan
    agent = make_agent("reasoner", {"backend": "grounder"})
    assert run_episode(right, agent, domain).success and agent.replans == 0


class _HelpfulExecutor:
    """A symbolic executor that, besides an accepted step, also moves another object (as a physical
    executor setting neighbours aside for a pick does): once it can, it puts blue_cube into the box."""

    def __init__(self) -> None:
        from gsr.symbolic_executor import SymbolicExecutor

        self.inner = SymbolicExecutor()
        self.moved = False

    def reset(self, task, domain):
        self.domain = domain
        return self.inner.reset(task, domain)

    def execute(self, step):
        from gsr.check import check_step
        from gsr.step import Step

        diagnosis = self.inner.execute(step)
        if diagnosis.ok and not self.moved:
            state = self.inner.state
            for side in (Step("pick", ("blue_cube", "table")), Step("place_in", ("blue_cube", "box"))):
                done = check_step(self.domain, state, side)
                if not done.ok:
                    break
                state = done.next_state
            else:
                self.inner.state, self.inner._stale, self.moved = state, True, True
        return diagnosis

    def graph(self):
        return self.inner.graph()


def test_planner_agent_plans_again_when_an_accepted_step_moved_other_objects(task, domain) -> None:
    # the agent's plan moves both cubes; after an accepted step the executor has put blue_cube in the
    # box itself: following the old plan would propose a pick of blue_cube from the table (rejected)
    both = task.model_copy(update={"goal_alternatives": ()})
    executor = _HelpfulExecutor()
    r = run_episode(both, make_agent("planner"), domain, executor=executor)
    assert executor.moved
    assert r.success and r.outcome == "true_success" and r.proposed == r.valid
    assert not any("blue_cube" in s for s in r.plan), r.plan
