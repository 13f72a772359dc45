"""The symbolic executor: the reference :class:`~gsr.episode.Executor`, steps applied by the PDDL checker.

No simulator: a step is checked with :func:`gsr.check.check_step` against the current state and, when
valid, the state advances to the checker's next state. The episode runner uses it by default;
executors with other rules build on it (GSR-Bench's validator rules, in the benchmarks layer),
and simulator executors implement the same protocol with observed states.
"""

from __future__ import annotations

from gsr.check import check_step
from gsr.diagnosis import Diagnosis
from gsr.facts import graph_with_state, state_from_graph
from gsr.pddl.model import Domain
from gsr.scene_graph import SceneGraph
from gsr.state import State
from gsr.step import Step
from gsr.task_spec import TaskSpec


class SymbolicExecutor:
    """Steps run on the symbolic state through the PDDL checker (no simulator)."""

    def __init__(self) -> None:
        self.domain: Domain | None = None
        self.state: State | None = None
        self._graph: SceneGraph | None = None
        self._stale = False

    def reset(self, task: TaskSpec, domain: Domain) -> State:
        """The task's initial graph as a state."""
        self.domain, self._graph, self._stale = domain, task.initial, False
        self.state = state_from_graph(task.initial, domain)
        return self.state

    def execute(self, step: Step) -> Diagnosis:
        """check_step; on success the state advances."""
        assert self.domain is not None and self.state is not None
        diagnosis = check_step(self.domain, self.state, step)
        if diagnosis.ok and diagnosis.next_state is not None:
            self.state, self._stale = diagnosis.next_state, True
        return diagnosis

    def graph(self) -> SceneGraph:
        """The graph of the current state (rebuilt lazily: agents that plan once never pay for it)."""
        assert self._graph is not None and self.state is not None
        if self._stale:
            self._graph, self._stale = graph_with_state(self._graph, self.state), False
        return self._graph
