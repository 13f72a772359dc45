"""The contract between the relaxation and its compiled kernels: the unary-operator arrays they read.

``gsr.plan.heuristics.Relaxation`` builds these arrays from a grounded task; the C kernels
(``gsr.plan.relax_c.CRelaxation``) and the numba ones (``gsr.plan.relax_jit.CompiledRelaxation``) copy
them into flat buffers. The kernels name this protocol, not the class, so they do not import the
heuristics module that drives them (the import graph stays acyclic: heuristics -> relax_jit -> relax_c,
all three -> this module).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:
    from gsr.plan.task import Task


@runtime_checkable
class UnaryRelaxation(Protocol):
    """A task's relaxation as unary operators over facts (atoms, their complements, auxiliary facts).

    Unary operator ``u`` needs the facts ``pre[u]`` (``npre[u]`` of them), adds ``add[u]`` at ``cost[u]``
    and stands for the task's operator ``owner[u]`` (-1: an auxiliary, axiom or goal operator);
    ``pre_of[f]`` lists the unary operators that need fact ``f``; ``comp`` maps an atom to its
    complement fact.
    """

    task: Task
    unit: bool  # every task operator costs 1 in the relaxation
    n_facts: int
    goal_fact: int  # reached when a goal disjunct holds
    true_fact: int  # always true: the precondition of an operator that needs nothing
    goal_stop: int  # the fact whose settling ends h_add early (-1: none)
    comp: dict[int, int]
    pre: list[tuple[int, ...]]
    add: list[tuple[int, ...]]
    cost: list
    owner: list[int]
    npre: list[int]
    pre_of: list[list[int]]
