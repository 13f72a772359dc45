"""``gsr plan DOMAIN PROBLEM [--planner NAME] [--timeout S] [--out PLAN]`` (wired into typer by gsr.cli)."""

from __future__ import annotations

import sys
from pathlib import Path

from gsr.errors import GSRError
from gsr.io import write_text_atomic
from gsr.pddl.bddl import load_bddl
from gsr.pddl.files import find_domain_file
from gsr.pddl.model import Domain, Problem
from gsr.pddl.parser import load_domain, load_problem
from gsr.plan.api import plan
from gsr.plan_format import write_plan
from gsr.resources import load_builtin_domain

EXIT_SOLVED, EXIT_ERROR, EXIT_UNSOLVABLE, EXIT_TIMEOUT = 0, 1, 2, 3


def load_libero(problem: Path, domain: Path | None) -> tuple[Domain, Problem]:
    """Domain and problem of a LIBERO ``.bddl`` task (the tabletop domain unless ``domain`` is given)."""
    from gsr.libero import libero_task  # builds a scene graph (pydantic): only for .bddl problems

    bddl = load_bddl(problem)
    if domain is not None and not domain.is_file():
        raise GSRError(f"{domain}: no such file")
    dom = load_domain(domain) if domain is not None else load_builtin_domain("tabletop")
    return dom, libero_task(bddl, dom)[1]


def load_task(domain: Path | None, problem: Path) -> tuple[Domain, Problem]:
    """Parse the domain and problem files (a ``.bddl`` problem plans against the tabletop domain)."""
    if not problem.is_file():
        raise GSRError(f"{problem}: no such file")
    if problem.suffix.lower() == ".bddl":
        return load_libero(problem, domain)
    if domain is None:
        domain = find_domain_file(problem)
        if domain is None:
            raise GSRError(
                f"{problem}: no domain file beside it (domain.pddl, {problem.stem}-domain.pddl, "
                f"domain_{problem.name}, ...): give DOMAIN PROBLEM"
            )
    if not domain.is_file():
        raise GSRError(f"{domain}: no such file")
    dom = load_domain(domain)
    return dom, load_problem(problem, dom)


def plan_command(domain: Path | None, problem: Path, planner: str, timeout: float, out: Path | None) -> int:
    """Plan and print the IPC plan (or write it to ``out``); stats on stderr; returns the exit code."""
    if not timeout >= 0:  # negative or NaN
        print(f"error: --timeout must be a number of seconds >= 0, not {timeout:g}", file=sys.stderr)
        return EXIT_ERROR
    try:
        dom, prob = load_task(Path(domain) if domain is not None else None, Path(problem))
        result = plan(dom, prob, planner=planner, timeout=timeout)
    except GSRError as err:
        print(f"error: {err}", file=sys.stderr)
        return EXIT_ERROR
    except OSError as err:
        print(f"error: {err}", file=sys.stderr)
        return EXIT_ERROR
    except (RecursionError, MemoryError) as err:
        print(f"error: the task is too large for the planner ({type(err).__name__})", file=sys.stderr)
        return EXIT_ERROR
    except Exception as err:  # the command's contract: one line, never a traceback
        print(
            f"error: internal planner error ({type(err).__name__}: {err}); please report it", file=sys.stderr
        )
        return EXIT_ERROR
    stats = (
        f"{result.planner}: {result.status} in {result.time:.3f} s (ground {result.ground_time:.3f} s, "
        f"search {result.search_time:.3f} s); expanded {result.expanded}, generated {result.generated}, "
        f"evaluated {result.evaluated}"
    )
    if result.status == "solved" and result.plan is not None:
        text = write_plan(result.plan, result.cost)
        try:
            if out is not None:
                write_text_atomic(Path(out), text)
            else:
                sys.stdout.write(text)
        except OSError as err:
            print(f"error: cannot write {out}: {err}", file=sys.stderr)
            return EXIT_ERROR
        cost = "unknown" if result.cost is None else f"{result.cost:g}"
        print(f"{stats}; plan length {len(result.plan)}, cost {cost}", file=sys.stderr)
        return EXIT_SOLVED
    print(f"{stats}; {result.message}", file=sys.stderr)
    if result.status == "unsolvable":
        return EXIT_UNSOLVABLE
    if result.status == "timeout":
        return EXIT_TIMEOUT
    return EXIT_ERROR
