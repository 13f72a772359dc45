"""The symbolic planner: ADL normalisation, grounding, heuristic search (and optional Fast Downward)."""

from gsr.plan.api import OPTIMAL, PLANNERS, PlanResult, plan, plan_graph
from gsr.plan.grounding import ground_task
from gsr.plan.task import GroundOp, Task

__all__ = ["OPTIMAL", "PLANNERS", "GroundOp", "PlanResult", "Task", "ground_task", "plan", "plan_graph"]
