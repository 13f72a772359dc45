"""GSR: grounded scene-graph reasoning for robot manipulation.

The public API is re-exported here (the planner lives in ``gsr.plan``: ``gsr.plan.plan(domain, problem)``) and imported lazily (PEP 562), so ``import gsr`` stays fast and
pulls in nothing heavy until a name is used::

    import gsr
    domain = gsr.load_builtin_domain()
    graph = gsr.graph_from_gsr_bench({"nodes": [...], "edges": [...]})
    print(gsr.check_step(domain, gsr.state_from_graph(graph, domain), step))
"""

from __future__ import annotations

from gsr.lazy import lazy_exports

__version__ = "0.1.0"

# public name -> module that defines it
_EXPORTS: dict[str, str] = {
    "SceneGraph": "gsr.scene_graph",
    "Node": "gsr.scene_graph",
    "Edge": "gsr.scene_graph",
    "Pose": "gsr.scene_graph",
    "BoundingBox": "gsr.scene_graph",
    "Keypoint": "gsr.scene_graph",
    "scene_graph_schema": "gsr.scene_graph",
    "Step": "gsr.step",
    "Plan": "gsr.step",
    "Goal": "gsr.step",
    "State": "gsr.state",
    "Diagnosis": "gsr.diagnosis",
    "Report": "gsr.validate",
    "GSRError": "gsr.errors",
    "ParseError": "gsr.errors",
    "Domain": "gsr.pddl.model",
    "Problem": "gsr.pddl.model",
    "parse_domain": "gsr.pddl.parser",
    "parse_problem": "gsr.pddl.parser",
    "load_domain": "gsr.pddl.parser",
    "load_problem": "gsr.pddl.parser",
    "load_bddl": "gsr.pddl.bddl",
    "write_domain": "gsr.pddl.writer",
    "write_problem": "gsr.pddl.writer",
    "write_formula": "gsr.pddl.writer",
    "facts": "gsr.facts",
    "state_from_graph": "gsr.facts",
    "problem_from_graph": "gsr.facts",
    "graph_with_state": "gsr.facts",
    "check_step": "gsr.check",
    "validate_plan": "gsr.validate",
    "apply_step": "gsr.transition",
    "apply_steps": "gsr.transition",
    "StepRejected": "gsr.transition",
    "diff_graphs": "gsr.graph_diff",
    "to_prompt_text": "gsr.graph_text",
    "graph_from_gsr_bench": "gsr.gsr_bench_format",
    "gsr_bench_message": "gsr.gsr_bench_format",
    "libero_task": "gsr.libero",
    "parse_plan": "gsr.plan_format",
    "load_plan": "gsr.plan_format",
    "write_plan": "gsr.plan_format",
    "load_builtin_domain": "gsr.resources",
    "plan_graph": "gsr.plan.api",
    "ground": "gsr.language",
    "GroundingError": "gsr.language",
    "solve": "gsr.reason",
    "ReasonResult": "gsr.reason",
    "TaskSpec": "gsr.task_spec",
    "Layout": "gsr.task_spec",
    "load_task": "gsr.task_spec",
    "scene_graph_svg": "gsr.graph_svg",
    "PlanResult": "gsr.plan.api",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports("gsr", _EXPORTS, globals())
