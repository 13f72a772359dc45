"""Scoring a perceived scene graph against ground truth: nodes, relations (P/R/F1), part states."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from gsr.scene_graph import SceneGraph

#: Relations scored by default (the ones perception infers).
SCORED_RELATIONS: tuple[str, ...] = ("on", "in", "adjacent", "left_of", "right_of", "front_of", "behind")
_PART_STATES = ("open", "closed")


@dataclass
class Counts:
    """True positives, false positives and false negatives of one relation."""

    tp: int = 0
    fp: int = 0
    fn: int = 0

    def scores(self) -> dict[str, float | int]:
        """Precision, recall, F1 (1.0 when there was nothing to find and nothing was claimed)."""
        p = self.tp / (self.tp + self.fp) if self.tp + self.fp else 1.0
        r = self.tp / (self.tp + self.fn) if self.tp + self.fn else 1.0
        f1 = 2 * p * r / (p + r) if p + r else 0.0
        return {
            "precision": round(p, 4),
            "recall": round(r, 4),
            "f1": round(f1, 4),
            "tp": self.tp,
            "fp": self.fp,
            "fn": self.fn,
        }


@dataclass
class Score:
    """Accumulated comparison over one or more scenes (micro-averaged)."""

    relations: dict[str, Counts] = field(default_factory=dict)
    truth_nodes: int = 0
    found_nodes: int = 0
    predicted_nodes: int = 0
    states_total: int = 0
    states_correct: int = 0
    states_observed: int = 0  # truth parts that were perceived at all
    opening_errors: list[float] = field(default_factory=list)  # |perceived - true| drawer opening (m)
    angle_errors: list[float] = field(default_factory=list)  # |perceived - true| door angle (rad)
    scenes: int = 0

    def add(
        self, predicted: SceneGraph, truth: SceneGraph, relations: tuple[str, ...] = SCORED_RELATIONS
    ) -> None:
        """Compare one perceived graph with its ground truth and accumulate."""
        self.scenes += 1
        pred_nodes, true_nodes = predicted.node_map(), truth.node_map()
        self.truth_nodes += len(true_nodes)
        self.predicted_nodes += len(pred_nodes)
        self.found_nodes += len(set(pred_nodes) & set(true_nodes))
        for rel in relations:
            t = {e.key() for e in truth.edges if e.relation == rel}
            p = {e.key() for e in predicted.edges if e.relation == rel}
            c = self.relations.setdefault(rel, Counts())
            c.tp += len(t & p)
            c.fp += len(p - t)
            c.fn += len(t - p)
        for node_id, node in true_nodes.items():
            want = [s for s in node.states if s in _PART_STATES]
            if not want:
                continue
            self.states_total += 1
            got = pred_nodes.get(node_id)
            if got is None:
                continue
            self.states_observed += 1
            self.states_correct += int([s for s in got.states if s in _PART_STATES] == want)
            for key, errors in (("open_distance", self.opening_errors), ("open_angle", self.angle_errors)):
                if key in node.attributes and key in got.attributes:
                    errors.append(abs(float(got.attributes[key]) - float(node.attributes[key])))

    def to_dict(self) -> dict[str, Any]:
        """The report: ``{"nodes", "relations": {rel: {precision, recall, f1}}, "states", ...}``."""

        def mean(xs: list[float]) -> float | None:
            return round(sum(xs) / len(xs), 4) if xs else None

        return {
            "scenes": self.scenes,
            "nodes": {
                "truth": self.truth_nodes,
                "found": self.found_nodes,
                "predicted": self.predicted_nodes,
                "recall": round(self.found_nodes / self.truth_nodes, 4) if self.truth_nodes else 1.0,
                "precision": round(self.found_nodes / self.predicted_nodes, 4)
                if self.predicted_nodes
                else 1.0,
            },
            "relations": {rel: c.scores() for rel, c in self.relations.items()},
            "states": {
                "total": self.states_total,
                "observed": self.states_observed,
                "correct": self.states_correct,
                "accuracy": round(self.states_correct / self.states_total, 4) if self.states_total else 1.0,
                "accuracy_observed": (
                    round(self.states_correct / self.states_observed, 4) if self.states_observed else 1.0
                ),
                "drawer_opening_mae_m": mean(self.opening_errors),
                "door_angle_mae_rad": mean(self.angle_errors),
            },
        }


def score(
    predicted: SceneGraph, truth: SceneGraph, relations: tuple[str, ...] = SCORED_RELATIONS
) -> dict[str, Any]:
    """The report for a single scene."""
    s = Score()
    s.add(predicted, truth, relations)
    return s.to_dict()


#: Why a truth ``in`` relation was missed / why a perceived one is false (docs/perception.md, Evaluation).
MISSED_CAUSES = (
    "hidden_closed",  # the object is shown by no camera and its container is closed
    "hidden_other",  # shown by no camera, container open (occluded)
    "object_not_perceived",  # visible, but no perceived node is it
    "container_not_perceived",  # the object was perceived, its container was not
    "on_instead_of_in",  # both perceived, the object is put on something
    "wrong_container",  # both perceived, the object is put in another container
    "no_support",  # both perceived, no support edge for the object
)
FALSE_CAUSES = (
    "unmatched_object",  # a perceived node that is no truth object (a fragment, a duplicate) is "in"
    "unmatched_container",  # a real object is "in" a perceived node that is no truth object
    "wrong_container",  # the object is in another container in the truth
    "in_instead_of_on",  # the object rests on something in the truth
    "other",  # e.g. held or unsupported in the truth
)


def classify_in_errors(
    predicted: SceneGraph, truth: SceneGraph, visible: set[str], perceived: set[str]
) -> list[tuple[str, str, str, str]]:
    """Every ``in`` relation of one scene as ``(kind, object, container, cause)``: kind ``tp`` (cause ""),
    ``missed`` (a truth relation not perceived, cause of MISSED_CAUSES) or ``false`` (a perceived relation
    not in the truth, cause of FALSE_CAUSES). Arguments as :class:`ContainmentErrors`."""
    t_in = {(e.source, e.target) for e in truth.edges if e.relation == "in"}
    t_sup = {e.source: (e.relation, e.target) for e in truth.edges if e.relation in ("on", "in")}
    p_in = {(e.source, e.target) for e in predicted.edges if e.relation == "in"}
    p_sup = {e.source: (e.relation, e.target) for e in predicted.edges if e.relation in ("on", "in")}
    truth_ids = {n.id for n in truth.nodes}
    nodes = truth.node_map()
    out: list[tuple[str, str, str, str]] = []
    for a, c in sorted(t_in):
        if (a, c) in p_in:
            out.append(("tp", a, c, ""))
            continue
        if a not in visible:
            closed = c in nodes and "closed" in nodes[c].states
            cause = "hidden_closed" if closed else "hidden_other"
        elif a not in perceived:
            cause = "object_not_perceived"
        elif c not in perceived:
            cause = "container_not_perceived"
        elif a not in p_sup:
            cause = "no_support"
        else:
            cause = "wrong_container" if p_sup[a][0] == "in" else "on_instead_of_in"
        out.append(("missed", a, c, cause))
    for a, c in sorted(p_in - t_in):
        if a not in truth_ids:
            cause = "unmatched_object"
        elif c not in truth_ids:
            cause = "unmatched_container"
        elif t_sup.get(a, ("", ""))[0] == "in":
            cause = "wrong_container"
        elif t_sup.get(a, ("", ""))[0] == "on":
            cause = "in_instead_of_on"
        else:
            cause = "other"
        out.append(("false", a, c, cause))
    return out


@dataclass
class ContainmentErrors:
    """Counts of the ``in`` relation's errors by cause, over scenes (see MISSED_CAUSES, FALSE_CAUSES).

    ``predicted`` must already carry the truth's ids (a perceived node paired with no truth node has an id
    the truth does not use); ``visible``: truth ids some camera shows; ``perceived``: truth ids paired
    with a perceived node."""

    true_positive: int = 0
    missed: dict[str, int] = field(default_factory=lambda: dict.fromkeys(MISSED_CAUSES, 0))
    false: dict[str, int] = field(default_factory=lambda: dict.fromkeys(FALSE_CAUSES, 0))

    def add(self, predicted: SceneGraph, truth: SceneGraph, visible: set[str], perceived: set[str]) -> None:
        """Classify one scene's ``in`` errors."""
        for kind, _, _, cause in classify_in_errors(predicted, truth, visible, perceived):
            if kind == "tp":
                self.true_positive += 1
            else:
                getattr(self, kind)[cause] += 1

    def to_dict(self) -> dict[str, Any]:
        """``{"tp", "missed": {cause: n}, "false": {cause: n}}``."""
        return {"tp": self.true_positive, "missed": dict(self.missed), "false": dict(self.false)}
