"""Train a compact-format step model from scratch (:mod:`gsr.reason.compact`): data, training, DAgger.

Data (all labels come from the planner, all states from the project's generator):

- **trajectory rows**: every ``next_action`` row of a ``gsr datagen`` dataset (state, goal, history ->
  the planner's next step, or ``done``);
- **recovery rows**: a trajectory state knocked off the plan by one or two random applicable steps,
  labelled with the first step of a fresh plan from there (the model learns to recover, not only to
  follow an optimal path);
- **on-policy rows (DAgger)**: states the trained model itself visits on training tasks, labelled by
  the planner, added before training on.

Each row is written with a fresh random object naming every time it is used (augmentation). The model
is a small ``LlamaForCausalLM`` with the word-level domain tokenizer; the loss is on the answer tokens.
The output folder (written atomically) loads with ``--backend transformers:DIR``.
"""

from __future__ import annotations

import glob
import json
import math
import os
import random
import shutil
import time
from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from gsr.check import check_step
from gsr.datagen.schema import decode
from gsr.errors import GSRError, ParseError
from gsr.facts import graph_with_state, state_from_graph
from gsr.pddl.model import Domain, Formula
from gsr.pddl.parser import parse_formula
from gsr.plan import api as plan_api  # called through the module: counters patch plan_api.plan_graph
from gsr.reason.applicable import applicable_steps
from gsr.reason.backend import Query
from gsr.reason.compact import (
    EOS,
    FORMATS,
    HISTORY,
    MARKER,
    MAX_OBJECTS,
    Naming,
    action_tokens,
    context_tokens,
    scene_objects,
)
from gsr.reason.compact_decode import CompactAnswerer, answer_key, window_goal
from gsr.reason.prompt import Prompt
from gsr.reason.step_format import format_step, parse_first_step
from gsr.scene_graph import SceneGraph
from gsr.semantics import goal_holds
from gsr.step import Step
from gsr.train.format import read_rows
from gsr.train.tiny import tiny_model


@dataclass(frozen=True)
class Sample:
    """One supervised next-step decision: the scene now, the goal, the steps so far, the planner's answer."""

    graph: SceneGraph
    goal: Formula
    history: tuple[Step, ...]
    answer: Step | None  # None: the goal holds (answer ``done``)
    source: str = "trajectory"


@dataclass(frozen=True)
class CompactSpec:
    """Size of the compact model (defaults: ~0.5M parameters, trains on one CPU core in minutes)."""

    hidden: int = 128
    layers: int = 3
    heads: int = 4
    intermediate: int = 256
    context: int = 512


def dataset_samples(data: Path, split: str = "train", limit: int | None = None) -> list[Sample]:
    """Trajectory samples from a ``gsr datagen`` folder's ``next_action`` rows."""
    files = sorted(glob.glob(str(data / "data" / split / "*.jsonl")))
    if not files:
        raise GSRError(f"{data}: no data/{split}/*.jsonl files (generate them with gsr datagen)")
    out: list[Sample] = []
    for row in read_rows(files, ("next_action",), limit):
        _, inp, res = decode(row)
        history = tuple(Step(s.action, tuple(s.args)) for s in inp.history)
        answer = None if res.done else Step(res.step.action, tuple(res.step.args))
        out.append(Sample(inp.graph, parse_formula(inp.goal), history, answer))
    return out


def _apply(domain: Domain, graph: SceneGraph, step: Step) -> SceneGraph | None:
    diagnosis = check_step(domain, state_from_graph(graph, domain), step)
    return graph_with_state(graph, diagnosis.next_state) if diagnosis.ok else None


def label(
    domain: Domain, graph: SceneGraph, goal: Formula, timeout: float = 10.0
) -> tuple[bool, Step | None]:
    """The planner's next step from ``graph``: (solvable, step; None when the goal already holds)."""
    if goal_holds(domain, goal, state_from_graph(graph, domain)):
        return True, None
    found = plan_api.plan_graph(domain, graph, goal, timeout=timeout)
    if not found.solved or found.plan is None or not found.plan.steps:
        return False, None
    first = found.plan.steps[0]
    return True, Step(first.action, first.args)


def recovery_samples(
    samples: Sequence[Sample], count: int, seed: int, domain: Domain, budget: float | None = None
) -> list[Sample]:
    """Off-plan states (1-2 random applicable steps away from a trajectory) with the planner's recovery step."""
    rng = random.Random(seed)
    pool = [s for s in samples if s.answer is not None]
    out: list[Sample] = []
    start = time.perf_counter()
    while pool and len(out) < count and (budget is None or time.perf_counter() - start < budget):
        base = rng.choice(pool)
        graph, history = base.graph, list(base.history)
        for _ in range(rng.choice((1, 1, 2))):
            options = [s for s in applicable_steps(domain, graph) if (s.action, s.args) != _key(base.answer)]
            if not options:
                break
            step = rng.choice(options)
            graph = _apply(domain, graph, Step(step.action, step.args)) or graph
            history.append(Step(step.action, step.args))
        ok, step = label(domain, graph, base.goal)
        if ok:
            out.append(Sample(graph, base.goal, tuple(history), step, "recovery"))
    return out


def windowed_samples(
    samples: Sequence[Sample], domain: Domain, limit: int, order: str = "goal"
) -> list[Sample]:
    """The rows as a model decoding with a goal window of ``limit`` sees them
    (:func:`gsr.reason.compact_decode.window_goal`): a row with more than ``limit`` open goal literals gets
    the windowed goal (every holding literal, the first ``limit`` open ones in ``order``) and the planner's
    first step
    for that goal, so training and decoding show the model the same goals and the label serves a shown
    literal. Other rows are kept as they are; a windowed row the planner cannot label is dropped."""
    out: list[Sample] = []
    for s in samples:
        shown = window_goal(s.goal, s.graph, domain, limit, order)
        if shown is s.goal:
            out.append(s)
            continue
        ok, step = label(domain, s.graph, shown)
        if ok:
            out.append(Sample(s.graph, shown, s.history, step, s.source))
    return out


def planner_samples(
    tasks: Iterable[tuple[SceneGraph, Formula]],
    domain: Domain,
    goal_window: int | None = None,
    goal_order: str = "goal",
    max_steps: int = 40,
) -> list[Sample]:
    """Rows of the planner's own episodes on ``tasks`` (the recipe's joined training tasks): from each
    start, the goal as decoding shows it (through ``goal_window`` in ``goal_order``, else the whole goal),
    labelled with the planner's first step for that goal, which is then taken, until the whole goal holds
    (a ``done`` row). An episode the planner cannot continue keeps the rows it has."""
    out: list[Sample] = []
    for graph, goal in tasks:
        history: list[Step] = []
        for _ in range(max_steps + 1):
            shown = window_goal(goal, graph, domain, goal_window, goal_order) if goal_window else goal
            ok, step = label(domain, graph, shown)
            if not ok:
                break
            out.append(Sample(graph, shown, tuple(history), step, "joined"))
            nxt = None if step is None else _apply(domain, graph, step)
            if nxt is None:
                break
            graph = nxt
            history.append(step)
    return out


def _key(step: Step | None) -> tuple | None:
    return None if step is None else (step.action, step.args)


def encode(
    sample: Sample,
    domain: Domain,
    vocab: dict[str, int],
    rng: random.Random | None,
    version: int = 1,
) -> tuple[list[int], int]:
    """(token ids of context + answer + eos, context length) under a fresh random naming (the
    inference naming, sorted names, when ``rng`` is None)."""
    state = state_from_graph(sample.graph, domain)
    naming = Naming.make(scene_objects(state, domain), rng)
    context = context_tokens(state, domain, sample.goal, sample.history, naming, version)
    answer = [*action_tokens(sample.answer, naming), EOS]
    return [vocab[t] for t in context + answer], len(context)


def new_model(tokenizer: Any, spec: CompactSpec, seed: int) -> Any:
    """A freshly initialised LlamaForCausalLM for the word-level vocabulary (the same Llama shape as the
    tiny models: ``spec`` gives hidden, intermediate, layers, heads and context)."""
    return tiny_model(tokenizer, spec, seed)


@dataclass
class FitReport:
    """What one call of :func:`fit` did."""

    steps: int
    examples: int
    seconds: float
    cpu_seconds: float
    last_loss: float
    selected_step: int | None = None  # the step whose weights were kept (selection), else the last
    selection: list[tuple[int, float]] | None = None  # (step, score) of every selection evaluation


def fit(
    model: Any,
    samples: Sequence[Sample],
    domain: Domain,
    vocab: dict[str, int],
    seconds: float,
    seed: int,
    batch_size: int = 32,
    lr: float = 2e-3,
    optimizer: Any = None,
    schedule: Callable[[float], float] | None = None,
    log: Callable[[str], None] = print,
    max_steps: int | None = None,
    version: int = 1,
    shuffle_names: bool = True,
    group: int = 1,
    select: Callable[[Any], float] | None = None,
    select_every: int = 0,
) -> tuple[FitReport, Any]:
    """Train ``model`` on ``samples``; loss on the answer tokens. Returns the optimizer too.

    With ``max_steps`` the run is ``max_steps`` steps and ``schedule`` reads the share of steps done, so a
    seed gives the same training on any machine and at any load; ``seconds`` of this process's CPU time
    is then only a cap. Without it the run is ``seconds`` of CPU time and the schedule reads the share of
    that time: how many steps that is, and so the learning rate at each step, moves with the machine and
    its load (measured: 1408-1537 first-round steps in 600 CPU-s on one machine, and the trained model's
    success with them).

    ``group`` > 1 draws ``group`` batches at once, sorts their rows by length and trains on the batches
    of similar length in a random order (less padding: ~25% less CPU per example on the compact rows).
    ``select`` scores the model (higher is better, e.g. :func:`ranking_accuracy` on validation rows)
    every ``select_every`` steps and at the end; the best-scoring weights are kept (the later on a tie)
    and the report lists every score."""
    import torch

    if not samples:
        raise GSRError("no training samples")
    rng = random.Random(seed)
    pad = vocab["<pad>"]
    opt = optimizer or torch.optim.AdamW(model.parameters(), lr=lr, weight_decay=0.01, betas=(0.9, 0.98))
    model.train()
    t0, c0 = time.perf_counter(), time.process_time()
    steps = examples = 0
    loss_value = float("nan")
    order: list[int] = []
    pending: list[list[tuple[list[int], int]]] = []
    scores: list[tuple[int, float]] = []
    best: tuple[float, int, dict[str, Any]] | None = None

    def consider() -> None:
        nonlocal best
        if select is None:
            return
        model.eval()
        score = float(select(model))
        model.train()
        scores.append((steps, round(score, 4)))
        log(f"step {steps}: selection score {score:.4f}")
        if best is None or score >= best[0]:
            best = (score, steps, {k: v.detach().clone() for k, v in model.state_dict().items()})

    while time.process_time() - c0 < seconds and (max_steps is None or steps < max_steps):
        if not pending:
            want = batch_size * max(1, group)
            while len(order) < want:
                order += rng.sample(range(len(samples)), len(samples))
            rows = [
                encode(samples[order.pop()], domain, vocab, rng if shuffle_names else None, version)
                for _ in range(want)
            ]
            if group > 1:
                rows.sort(key=lambda r: len(r[0]))
            pending = [rows[i : i + batch_size] for i in range(0, want, batch_size)]
            if group > 1:
                rng.shuffle(pending)
        batch = pending.pop()
        width = max(len(ids) for ids, _ in batch)
        ids = torch.full((len(batch), width), pad, dtype=torch.long)
        labels = torch.full((len(batch), width), -100, dtype=torch.long)
        attn = torch.zeros((len(batch), width), dtype=torch.long)
        for k, (seq, cut) in enumerate(batch):
            ids[k, : len(seq)] = torch.tensor(seq)
            labels[k, cut : len(seq)] = torch.tensor(seq[cut:])
            attn[k, : len(seq)] = 1
        if schedule is not None:
            done = steps / max_steps if max_steps is not None else (time.process_time() - c0) / seconds
            for param_group in opt.param_groups:
                param_group["lr"] = lr * schedule(min(1.0, done))
        loss = model(input_ids=ids, attention_mask=attn, labels=labels).loss
        opt.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()
        steps += 1
        examples += len(batch)
        loss_value = float(loss.detach())
        if steps % 50 == 0:
            log(f"step {steps}: loss {loss_value:.4f}, {time.process_time() - c0:.0f} CPU s")
        if select is not None and select_every and steps % select_every == 0:
            consider()
    if select is not None and (not scores or scores[-1][0] != steps):
        consider()
    model.eval()
    selected = steps
    if best is not None:
        model.load_state_dict(best[2])
        selected = best[1]
    report = FitReport(
        steps,
        examples,
        round(time.perf_counter() - t0, 1),
        round(time.process_time() - c0, 1),
        loss_value,
        selected,
        scores,
    )
    return report, opt


def accuracy(
    model: Any, samples: Sequence[Sample], domain: Domain, tokenizer: Any, version: int = 1
) -> float:
    """Share of samples whose free (beam) answer equals the planner's label (exact action and arguments)."""
    if not samples:
        return float("nan")
    answerer = CompactAnswerer(model, tokenizer, version=version)
    hits = 0
    for s in samples:
        query = Query("step", Prompt("", ""), s.graph, domain, "", s.goal, s.history)
        reply = answerer.answer(query)
        hits += answer_key(reply) == (_key(s.answer) or ("done", ()))
    return hits / len(samples)


def ranking_accuracy(
    model: Any, samples: Sequence[Sample], domain: Domain, tokenizer: Any, version: int = 1
) -> float:
    """What constrained decoding sees offline: the share of samples with a step label whose planner step
    the model scores best among all the steps applicable in the sample's state (rows answered ``done``
    are left out: the loop stops when the goal holds). Free-decoding accuracy (:func:`accuracy`) also
    counts answers that are not applicable at all, which constrained decoding never gives."""
    answerer = CompactAnswerer(model, tokenizer, version=version)
    hits = total = 0
    for s in samples:
        if s.answer is None:
            continue
        lines = tuple(format_step(a) for a in applicable_steps(domain, s.graph))
        total += 1
        if len(lines) == 1:
            hits += answer_key(lines[0]) == _key(s.answer)
            continue
        query = Query("step", Prompt("", ""), s.graph, domain, "", s.goal, s.history, lines)
        hits += answer_key(answerer.answer(query)) == _key(s.answer)
    return hits / total if total else float("nan")


def admissible(
    domain: Domain, graph: SceneGraph, seen: Counter[frozenset]
) -> tuple[list[Step], list[Any], tuple[str, ...]]:
    """Constrained decoding's choice set, as the reasoner loop builds it: (applicable steps, their next
    states, the lines of those whose next state was visited least often in ``seen``)."""
    state = state_from_graph(graph, domain)
    steps = applicable_steps(domain, graph)
    nexts = [check_step(domain, state, s).next_state for s in steps]
    visits = [seen[n.atoms] for n in nexts]
    least = min(visits, default=0)
    lines = tuple(format_step(s) for s, v in zip(steps, visits, strict=True) if v == least)
    return steps, nexts, lines


def picked_index(steps: Sequence[Step], reply: str) -> int | None:
    """Index of the step in ``steps`` that the model's ``reply`` names, or None when it names none."""
    key = answer_key(reply)
    return next((i for i, s in enumerate(steps) if (s.action, s.args) == key), None)


def constrained_choice(
    answerer: CompactAnswerer,
    domain: Domain,
    graph: SceneGraph,
    goal: Formula,
    history: Sequence[Step],
    choices: tuple[list[Step], list[Any], tuple[str, ...]],
    seen: Counter[frozenset],
) -> tuple[int, SceneGraph, Any] | None:
    """One constrained-decoding step over :func:`admissible`'s ``choices``: the model picks among the
    admissible lines; (the picked step's index, the graph after it, its state), the state counted in
    ``seen``; None when the model names no admissible step."""
    steps, nexts, lines = choices
    query = Query("step", Prompt("", ""), graph, domain, "", goal, tuple(history), lines)
    k = picked_index(steps, answerer.answer(query))
    if k is None:
        return None
    graph = graph_with_state(graph, nexts[k])
    state = state_from_graph(graph, domain)
    seen[state.atoms] += 1
    return k, graph, state


@dataclass(frozen=True)
class ConstrainedEpisode:
    """One closed-loop episode under constrained decoding: ``graphs`` the scene before each step and
    after the last (``len(steps) + 1``), ``steps`` the model's picks, ``end`` why it stopped:
    ``"solved"`` (the goal holds), ``"max_steps"``, ``"no_admissible"`` (no applicable step) or
    ``"no_pick"`` (the model named no admissible step; a decision was made in ``graphs[-1]``)."""

    graphs: list[SceneGraph]
    steps: list[Step]
    end: str


def constrained_episode(
    answerer: CompactAnswerer, domain: Domain, graph: SceneGraph, goal: Formula, max_steps: int
) -> ConstrainedEpisode:
    """Run one episode as the reasoner loop does under constrained decoding (the admissible steps are
    the applicable ones whose next state the episode has visited least), until the goal holds,
    ``max_steps`` steps, no admissible step or no pick: the episode of :func:`constrained_episodes`
    and of ``gsr.train.diagnose``."""
    graphs = [graph]
    steps: list[Step] = []
    seen: Counter[frozenset] = Counter()
    state = state_from_graph(graph, domain)
    seen[state.atoms] += 1
    while True:
        if goal_holds(domain, goal, state):
            return ConstrainedEpisode(graphs, steps, "solved")
        if len(steps) == max_steps:
            return ConstrainedEpisode(graphs, steps, "max_steps")
        choices = admissible(domain, graph, seen)
        if not choices[0]:
            return ConstrainedEpisode(graphs, steps, "no_admissible")
        picked = constrained_choice(answerer, domain, graph, goal, steps, choices, seen)
        if picked is None:
            return ConstrainedEpisode(graphs, steps, "no_pick")
        k, graph, state = picked
        steps.append(Step(choices[0][k].action, choices[0][k].args))
        graphs.append(graph)


def constrained_episodes(
    model: Any,
    tokenizer: Any,
    tasks: Iterable[tuple[SceneGraph, Formula]],
    domain: Domain,
    max_steps: int = 24,
    version: int = 1,
    goal_window: int | None = None,
    goal_order: str = "goal",
) -> tuple[int, int]:
    """Closed-loop episodes under constrained decoding, as the reasoner loop runs them (the admissible
    steps are the applicable ones whose next state the episode has visited least), without the runner:
    (episodes whose goal held within ``max_steps``, episodes). A selection metric on validation tasks.
    ``goal_window``, ``goal_order``: the answerer's goal window and order (as the model's marker sets them
    for the backend)."""
    answerer = CompactAnswerer(
        model, tokenizer, version=version, goal_window=goal_window, goal_order=goal_order
    )
    solved = episodes = 0
    for graph, goal in tasks:
        episodes += 1
        solved += constrained_episode(answerer, domain, graph, goal, max_steps).end == "solved"
    return solved, episodes


def rollout_samples(
    model: Any,
    tokenizer: Any,
    tasks: Iterable[tuple[SceneGraph, Formula]],
    domain: Domain,
    max_steps: int = 12,
    budget: float | None = None,
    version: int = 1,
    constrained: bool = False,
    goal_window: int | None = None,
    goal_order: str = "goal",
) -> tuple[list[Sample], int]:
    """DAgger: run the model (free decoding, no checker; or, ``constrained``, choosing among the
    admissible steps as constrained decoding does) on ``tasks``; label every visited state with the
    planner. Returns (samples, episodes the model solved on its own). With ``goal_window`` the model
    decodes through that window (``goal_order``) and each visited state is labelled for (and keeps) the
    windowed goal (:func:`windowed_samples`' rows)."""
    answerer = CompactAnswerer(
        model, tokenizer, version=version, goal_window=goal_window, goal_order=goal_order
    )
    out: list[Sample] = []
    solved = 0
    start = time.perf_counter()
    for graph, goal in tasks:
        if budget is not None and time.perf_counter() - start > budget:
            break
        history: list[Step] = []
        seen: Counter[frozenset] = Counter([state_from_graph(graph, domain).atoms])
        for _ in range(max_steps):
            shown = window_goal(goal, graph, domain, goal_window, goal_order) if goal_window else goal
            ok, want = label(domain, graph, shown)
            if not ok:
                break
            out.append(Sample(graph, shown, tuple(history), want, "dagger"))
            if want is None:
                solved += 1
                break
            if constrained:
                choices = admissible(domain, graph, seen)
                picked = (
                    constrained_choice(answerer, domain, graph, goal, history, choices, seen)
                    if choices[0]
                    else None
                )
                if picked is None:
                    break
                graph = picked[1]
                history.append(choices[0][picked[0]])
                continue
            reply = answerer.answer(Query("step", Prompt("", ""), graph, domain, "", goal, tuple(history)))
            try:
                step = parse_first_step(reply, source="reply")
            except ParseError:
                break
            nxt = _apply(domain, graph, Step(step.action, step.args))
            if nxt is None:
                break
            graph = nxt
            history.append(Step(step.action, step.args))
    return out, solved


def save(
    model: Any,
    tokenizer: Any,
    out: Path,
    info: dict[str, Any],
    version: int = 1,
    goal_window: int | None = None,
    goal_order: str = "goal",
) -> None:
    """Write the folder to a temporary name and rename it to ``out`` (never half-written). ``goal_window``
    goes into the marker: the backend's answerer then shows the model at most that many goal literals
    that do not hold yet (:func:`gsr.reason.compact_decode.window_goal`), entering in ``goal_order``
    (written only when it is not the goal's own order, so such markers read as before)."""
    if out.exists() and any(out.iterdir()):
        raise GSRError(f"{out} exists and is not empty; choose a new output folder")
    tmp = out.with_name(f".{out.name}.tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    model.save_pretrained(tmp)
    tokenizer.save_pretrained(tmp)
    fmt = {v: k for k, v in FORMATS.items()}[version]  # the format version the model was trained in
    marker: dict[str, Any] = {"format": fmt, "max_objects": MAX_OBJECTS, "history": HISTORY}
    if goal_window is not None:
        marker["goal_window"] = goal_window
    if goal_order != "goal":
        marker["goal_order"] = goal_order
    (tmp / MARKER).write_text(json.dumps(marker, indent=1))
    (tmp / "gsr_training.json").write_text(json.dumps(info, indent=1, default=str))
    if out.exists():
        out.rmdir()
    os.replace(tmp, out)


def cosine(warmup: float = 0.03, floor: float = 0.05) -> Callable[[float], float]:
    """A learning-rate multiplier over training progress in [0, 1]: linear warmup, cosine decay."""

    def f(p: float) -> float:
        if p < warmup:
            return max(0.05, p / warmup)
        return floor + (1 - floor) * 0.5 * (1 + math.cos(math.pi * (p - warmup) / (1 - warmup)))

    return f


def spec_dict(spec: CompactSpec) -> dict[str, Any]:
    """The spec as JSON-ready fields."""
    return asdict(spec)
