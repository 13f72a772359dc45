"""A tiny step model trained from scratch on planner traces, to measure constrained decoding on CPU.

    python -m gsr.reason.tiny_model OUT data/libero --split even --seconds 300

Each LIBERO task is solved by the planner from its benchmark goal; every step of the trace becomes one
(prompt, step line with its true effects) pair, with the compact prompt the measurement uses
(no examples, action signatures only, the goal shown). A byte-level BPE tokenizer and a small GPT-2
are trained on these pairs (loss on the answer tokens only) and saved to OUT as a local model folder
for the ``transformers:OUT`` backend. Deterministic for a seed (CPU, one thread order).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

from gsr.check import check_step
from gsr.errors import GSRError
from gsr.facts import graph_with_state, state_from_graph
from gsr.pddl.model import Atom
from gsr.plan import api as plan_api  # called through the module: counters patch plan_api.plan_graph
from gsr.reason.cases import PROMPT_OPTIONS, libero_cases, split_cases
from gsr.reason.examples import annotate_steps
from gsr.reason.prompt import build_prompt
from gsr.reason.step_format import format_step
from gsr.resources import load_builtin_domain
from gsr.step import Goal


def random_goals(graph: Any, count: int, seed: int) -> list[tuple[Any, str]]:
    """``count`` seeded single-placement goals in a scene: (goal formula, instruction)."""
    import random

    atoms = state_from_graph(graph, load_builtin_domain()).atoms
    movable = sorted(a.args[0] for a in atoms if a.predicate == "movable")
    targets = sorted(
        (a.args[0], {"supporter": "on", "container": "in"}[a.predicate])
        for a in atoms
        if a.predicate in ("supporter", "container")
    )
    rng = random.Random(seed)
    out = []
    for _ in range(count if movable and targets else 0):
        obj = rng.choice(movable)
        target, rel = rng.choice([t for t in targets if t[0] != obj] or targets)
        out.append((Atom(rel, (obj, target)), f"put {obj} {rel} {target}"))
    return out


def trace_pairs(cases: list, goals_per_scene: int = 0, seed: int = 0) -> list[tuple[str, str]]:
    """(prompt text, answer line) for every planner step of every case (plus seeded random goals per scene)."""
    domain = load_builtin_domain()
    pairs = []
    tasks = []
    for i, (_name, graph, goal, instruction) in enumerate(cases):
        tasks.append((graph, goal, instruction))
        tasks.extend((graph, g, text) for g, text in random_goals(graph, goals_per_scene, seed * 1000 + i))
    for graph, goal, instruction in tasks:
        found = plan_api.plan_graph(domain, graph, Goal(goal, instruction))
        if not found.solved or found.plan is None:
            continue
        steps = annotate_steps(domain, graph, found.plan.steps)
        current = graph
        for i, step in enumerate(steps):
            prompt = build_prompt(
                current, domain, instruction, (), steps[:i], (), goal, PROMPT_OPTIONS["prompt_actions"]
            )
            pairs.append((prompt.text(), format_step(step)))

            diagnosis = check_step(domain, state_from_graph(current, domain), step)
            current = graph_with_state(current, diagnosis.next_state)
    return pairs


def train(
    out: Path,
    pairs: list[tuple[str, str]],
    seed: int = 0,
    seconds: float = 300.0,
    epochs: int = 200,
    n_embd: int = 128,
    n_layer: int = 2,
) -> dict:
    """Train tokenizer + GPT-2 on the pairs within the time budget; save to ``out``; return figures."""
    import torch
    from tokenizers import Tokenizer, decoders, models, pre_tokenizers, trainers
    from transformers import GPT2Config, GPT2LMHeadModel, PreTrainedTokenizerFast

    torch.manual_seed(seed)
    tok = Tokenizer(models.BPE())
    tok.pre_tokenizer = pre_tokenizers.ByteLevel(add_prefix_space=False)
    tok.decoder = decoders.ByteLevel()
    trainer = trainers.BpeTrainer(
        vocab_size=2000, special_tokens=["<eos>"], initial_alphabet=pre_tokenizers.ByteLevel.alphabet()
    )
    tok.train_from_iterator([p + a for p, a in pairs], trainer)
    fast = PreTrainedTokenizerFast(tokenizer_object=tok, eos_token="<eos>", pad_token="<eos>")
    eos = fast.eos_token_id
    rows = []
    for prompt, answer in pairs:
        p = fast(prompt, add_special_tokens=False)["input_ids"]
        a = fast(answer, add_special_tokens=False)["input_ids"] + [eos]
        rows.append((p + a, len(p)))
    longest = max(len(ids) for ids, _ in rows)
    config = GPT2Config(
        vocab_size=len(fast),
        n_positions=longest + 256,
        n_embd=n_embd,
        n_layer=n_layer,
        n_head=4,
        bos_token_id=eos,
        eos_token_id=eos,
    )
    model = GPT2LMHeadModel(config)
    optim = torch.optim.AdamW(model.parameters(), lr=2e-3, weight_decay=0.01)
    generator = torch.Generator().manual_seed(seed)
    start = time.perf_counter()
    done_epochs = 0
    loss_value = float("nan")
    model.train()
    while done_epochs < epochs and time.perf_counter() - start < seconds:
        order = torch.randperm(len(rows), generator=generator).tolist()
        for i in range(0, len(order), 8):
            if time.perf_counter() - start >= seconds:
                break
            batch = [rows[j] for j in order[i : i + 8]]
            width = max(len(ids) for ids, _ in batch)
            ids = torch.full((len(batch), width), eos)
            labels = torch.full((len(batch), width), -100)
            attn = torch.zeros((len(batch), width), dtype=torch.long)
            for k, (seq, cut) in enumerate(batch):
                ids[k, : len(seq)] = torch.tensor(seq)
                labels[k, cut : len(seq)] = torch.tensor(seq[cut:])  # loss on the answer only
                attn[k, : len(seq)] = 1
            loss = model(input_ids=ids, attention_mask=attn, labels=labels).loss
            optim.zero_grad()
            loss.backward()
            optim.step()
            loss_value = loss.detach().item()
        done_epochs += 1
        print(
            f"epoch {done_epochs}: loss {loss_value:.4f}, {time.perf_counter() - start:.0f} s",
            file=sys.stderr,
        )
    model.eval()
    out.mkdir(parents=True, exist_ok=True)
    fast.save_pretrained(out)
    model.save_pretrained(out)
    return {
        "pairs": len(pairs),
        "epochs": done_epochs,
        "final_loss": round(loss_value, 4),
        "seconds": round(time.perf_counter() - start, 1),
        "parameters": sum(p.numel() for p in model.parameters()),
        "max_tokens": longest,
        "mean_tokens": round(sum(len(ids) for ids, _ in rows) / len(rows)),
    }


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    import json

    parser = argparse.ArgumentParser(
        prog="python -m gsr.reason.tiny_model", description=__doc__.splitlines()[0]
    )
    parser.add_argument("out", type=Path)
    parser.add_argument("folder", type=Path, help="folder with LIBERO .bddl files")
    parser.add_argument("--split", default="even", help="train on all, even or odd tasks")
    parser.add_argument("--seconds", type=float, default=300.0)
    parser.add_argument("--epochs", type=int, default=200)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--goals-per-scene", type=int, default=20, help="extra seeded random goals per scene")
    args = parser.parse_args(argv)
    try:
        pairs = trace_pairs(
            split_cases(libero_cases(args.folder), args.split), args.goals_per_scene, args.seed
        )
        figures: dict[str, Any] = train(args.out, pairs, args.seed, args.seconds, args.epochs)
    except GSRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    print(json.dumps(figures))
    return 0


if __name__ == "__main__":
    sys.exit(main())
