"""Grounding: a PDDL domain and problem in, a ground ``Task`` of bitset operators out.

This ``__init__`` is the package's public API: code outside the package imports these names from
``gsr.plan.grounding`` and never reaches into its modules (``tests/test_layers.py`` checks it;
white-box tests may). The stages, in the order a ``ground_task`` call runs them:

- ``normalize``: an action's ADL precondition and effects into a ``Schema`` (negation normal form,
  flattened conditional effects, one schema per equality case; the normal forms are the formula
  walker's, ``gsr.pddl.walk.nnf`` / ``to_dnf``), and the per-binding ``ground_simplify`` other
  modules use on goals;
- ``simplify``: the ``Simplifier`` that expands quantifiers over typed objects (``ObjectsByType``)
  and folds statics and equalities away;
- ``precondition``: ground preconditions as atom keys (relaxed cores, DNF scans);
- ``compiled``: the per-schema precondition code generated once per domain (the fast path);
- ``effects``: effect blocks of an action being grounded (``Variant``) and the adds they queue;
- ``fixpoint``: the relaxed-reachability fixpoint over bindings, and ``ground_task`` itself;
- ``intern``: the reached actions and axioms turned into a ``Task`` (ids, masks, the goal).
"""

from gsr.plan.grounding.fixpoint import (
    GroundingTables,
    GroundingTimeout,
    ground_task,
    grounding_tables,
    schema_bindings,
)
from gsr.plan.grounding.intern import ground_goal
from gsr.plan.grounding.normalize import ground_simplify, normalize_action
from gsr.plan.grounding.simplify import ObjectsByType

__all__ = [
    "GroundingTables",
    "GroundingTimeout",
    "ObjectsByType",
    "ground_goal",
    "ground_simplify",
    "ground_task",
    "grounding_tables",
    "normalize_action",
    "schema_bindings",
]
