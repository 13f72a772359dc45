"""The episode seams: what an agent, an executor and an episode suite must provide, and what an episode yields.

An *episode* runs one task: the executor sets up the task's scene, the agent is reset on the task and
then asked, again and again, for the next :class:`~gsr.step.Step` given the graph the executor shows;
the executor checks and executes each step and answers a :class:`~gsr.diagnosis.Diagnosis`. The episode
runner (``run_episode`` in the benchmarks layer) drives that loop and records an :class:`EpisodeResult`.

These are pure types with no behaviour, so every layer can name them: the core's open-loop agent
(``gsr.train.openloop``), the simulator executor of the skills layer and the benchmark agents and
executors all implement them, and the runner in the top layer uses them; no layer imports upward to
reach a contract. ``Agent`` and ``Executor`` are ``runtime_checkable``: ``isinstance(obj, Agent)``
checks that the methods (and ``name``) exist, not their signatures.

Optional hooks the runner reads with ``getattr`` when present (not part of the protocols, since most
implementers lack them):

- agent: ``rejected_proposals`` (answers rejected before a checked step came back, counted as proposed)
  and ``believed_goal`` (the goal the agent pursued; tells a wrong goal from a premature "done");
- executor: ``agent_task(task)`` (the task as the agent may see it, e.g. with the perceived initial
  graph), ``truth_state()`` (the world's ground truth, scored instead of the observed state),
  ``perceive`` with ``belief_state()`` (the agent's final observed state) and ``frames``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any, Protocol, runtime_checkable

from gsr.diagnosis import Diagnosis
from gsr.errors import GSRError
from gsr.pddl.model import Domain
from gsr.scene_graph import SceneGraph
from gsr.state import State
from gsr.step import Step
from gsr.task_spec import TaskSpec

#: How an episode ended: the goal holds in the world; the agent said done but the goal does not hold;
#: the agent reached a goal of its own that is not the task's; the agent failed, a step was rejected
#: too often or the step limit was reached.
OUTCOMES = ("true_success", "false_positive", "goal_error", "planning_error")


@runtime_checkable
class Agent(Protocol):
    """Given the current scene graph and the instruction, return the next step or None (done).

    ``reset`` starts an episode; ``act`` is then called until it answers ``None``, a step is rejected
    more often than the runner retries, or the step limit is reached. After a rejected step the runner
    may ask again with the checker's diagnosis as ``feedback``; after an accepted one ``feedback`` is
    that step's (ok) diagnosis. An agent that cannot produce a step raises :class:`AgentFailure`.
    """

    name: str

    def reset(self, task: TaskSpec, domain: Domain, seed: int) -> None:
        """Start an episode of ``task`` (the agent may read anything in it; only oracles read the goal)."""

    def act(self, graph: SceneGraph, instruction: str, feedback: Diagnosis | None = None) -> Step | None:
        """The next step, or None when the agent considers the task done."""


class AgentFailure(GSRError):
    """The agent could not produce a step (no plan, grounding failed, model error)."""


@runtime_checkable
class Executor(Protocol):
    """Executes validated-or-not steps and reports what happened (symbolic or physical).

    ``execute`` must check the step itself (an invalid step changes nothing) and answer a non-ok
    diagnosis for a rejected step or a failed execution; ``graph`` is what the agent observes next.
    """

    def reset(self, task: TaskSpec, domain: Domain) -> State:
        """Set up the task's initial scene; the initial symbolic state."""

    def execute(self, step: Step) -> Diagnosis:
        """Check and execute one step; ``ok`` with ``next_state`` when it ran."""

    def graph(self) -> SceneGraph:
        """The current scene graph (what the agent observes)."""


@dataclass(frozen=True)
class EpisodeOptions:
    """What ``gsr bench run`` asks of an episode suite (paths as given; None = the suite's default)."""

    agent: str | None = None
    seed: int = 0
    trials: int = 1
    limit: int | None = None
    source: str | None = None
    tasks: str | None = None
    split: str | None = None


class EpisodeSuite(Protocol):
    """A suite whose episodes are not PDDL-step tasks (e.g. in-building delivery).

    It prepares its own per-episode payloads, runs each through a module-level job function on the
    runner's pool (the runner's ``run_jobs``: local processes or Ray, results in job order) and turns
    the records into its own metrics, results document and Markdown report.
    """

    name: str
    agents: dict[str, str]  # agent name -> one-line description
    default_agent: str

    def prepare(self, options: EpisodeOptions) -> tuple[list[dict[str, Any]], Any]:
        """Check the options; the payloads (each with an ``id``) and the picklable job config."""

    def job(self) -> Callable[[dict[str, Any], int, Any], dict[str, Any]]:
        """The module-level ``fn(payload, trial, config) -> record`` a worker runs per episode."""

    def document(self, records: list[dict[str, Any]], config: Any, **meta: Any) -> dict[str, Any]:
        """The results.json document (``suite``, ``agent``, ``success_rate``, ``metrics``, ``tasks``...)."""

    def markdown(self, doc: dict[str, Any]) -> str:
        """The Markdown report of a results document."""

    def summary_text(self, doc: dict[str, Any]) -> str:
        """A few lines for the terminal."""


@dataclass
class EpisodeResult:
    """One episode's record (the rows of results.json); ``outcome`` is one of :data:`OUTCOMES`."""

    id: str
    suite: str
    category: str
    level: str | None
    trial: int
    seed: int
    success: bool
    score: float
    recall: float
    steps: int
    proposed: int
    valid: int
    outcome: str
    reason: str
    time: float
    best_alternative: int = 0
    failure: dict[str, Any] | None = None
    plan: list[str] = field(default_factory=list)
    reference_steps: int | None = None
    perceived_success: bool | None = None  # --perceive: the goal held in the agent's perceived graph
    frames: list[str] = field(default_factory=list)  # RGB frames saved for the report (paths under --out)

    @property
    def executability(self) -> float:
        """Valid steps / proposed steps (1.0 when nothing was proposed)."""
        return self.valid / self.proposed if self.proposed else 1.0

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form."""
        return {**asdict(self), "executability": round(self.executability, 6)}
