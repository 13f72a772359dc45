"""Where a PDDL problem's domain file is, by the naming conventions of the IPC collections."""

from __future__ import annotations

from pathlib import Path


def domain_candidates(problem: Path) -> list[Path]:
    """The domain files a problem may go with, in the order Fast Downward's driver tries them:
    ``domain.pddl`` beside it, ``NAME-domain.pddl``, ``PPP-domain.pddl`` (the first three
    characters, airport's ``p01-airport1-p1.pddl``), ``domain_NAME.pddl`` and ``domain-NAME.pddl``."""
    folder, name = problem.parent, problem.name
    stem, ext = problem.stem, problem.suffix
    names = [
        "domain.pddl",
        f"{stem}-domain{ext}",
        f"{name[:3]}-domain.pddl",
        f"domain_{name}",
        f"domain-{name}",
    ]
    return [folder / n for n in dict.fromkeys(names)]


def find_domain_file(problem: str | Path) -> Path | None:
    """The domain file of a problem (see domain_candidates), or None when there is none."""
    for candidate in domain_candidates(Path(problem)):
        if candidate.is_file() and candidate.resolve() != Path(problem).resolve():
            return candidate
    return None
