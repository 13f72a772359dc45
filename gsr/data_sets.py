"""Reference data sets: what ships in ``data/``, what ``gsr data fetch`` brings, and where each set is found.

Three kinds of reference data (see ``data/README.md``):

* **shipped** — small MIT-licensed subsets in the repository's ``data/`` folder (40 LIBERO task files,
  5 BEHAVIOR-100 activities), enough for the demo and the default tests;
* **fetched** — the full sets, downloaded from the Python package index by ``gsr data fetch NAME``: a
  pinned release file of a package is checked against the index's sha256 *and* the pinned one, its data
  files are extracted into a temporary folder inside the cache, and the folder is renamed into place, so
  a set in the cache is either complete or absent;
* **provided** — sets whose licence does not allow copying (GSR-Bench configs, PRS): never fetched or
  copied; the user points the project at them (``--source PATH`` or ``$GSR_SHARED_DATA``).

:func:`locate` finds a set: the fetched copy in the cache, else the reference folder
(``$GSR_SHARED_DATA`` or ``../shared/data``), else the shipped subset.
"""

from __future__ import annotations

import errno
import hashlib
import http.client
import json
import os
import shutil
import tarfile
import tempfile
import urllib.error
import urllib.parse
import urllib.request
import zipfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

from gsr.errors import GSRError
from gsr.resources import cache_dir, data_dir, shared_data_dir

DEFAULT_INDEX = "https://pypi.org/pypi"
MANIFEST = ".gsr-data.json"
CHUNK = 1 << 16

Progress = Callable[[int, int], None]  # (bytes so far, total bytes or 0 when unknown)


def _libero_member(name: str) -> str | None:
    """``libero-0.1.1/libero/libero/bddl_files/SUITE/TASK.bddl`` -> ``SUITE/TASK.bddl``."""
    parts = name.split("/")
    if len(parts) == 6 and parts[1:4] == ["libero", "libero", "bddl_files"] and parts[5].endswith(".bddl"):
        return f"{parts[4]}/{parts[5]}"
    return None


def _behavior_member(name: str) -> str | None:
    """``bddl-1.0.1/bddl/activity_definitions/ACT/problem0.bddl`` -> ``ACT.bddl``; the domain file as is."""
    parts = name.split("/")
    if len(parts) < 4 or parts[1:3] != ["bddl", "activity_definitions"]:
        return None
    if len(parts) == 4 and parts[3].startswith("domain_") and parts[3].endswith(".bddl"):
        return parts[3]
    if len(parts) == 5 and parts[4] == "problem0.bddl":
        return f"{parts[3]}.bddl"
    return None


def _pddlgym_members(names: list[str]) -> Callable[[str], str | None]:
    """pddlgym's ``pddl/D.pddl``, ``pddl/D/P.pddl``, ``pddl/D_test/P.pddl`` -> ``D/domain.pddl``,
    ``D/P.pddl``, ``D/test/P.pddl`` (problem folders without a domain file of their own are left out)."""
    prefix = "pddlgym/pddl/"
    domains = {
        n[len(prefix) : -5]
        for n in names
        if n.startswith(prefix) and n.endswith(".pddl") and n.count("/") == 2
    }

    def select(name: str) -> str | None:
        if not name.startswith(prefix) or not name.endswith(".pddl"):
            return None
        rest = name[len(prefix) :].split("/")
        if len(rest) == 1:
            return f"{rest[0][:-5]}/domain.pddl"
        if len(rest) != 2:
            return None
        folder, file = rest
        if folder in domains:
            return f"{folder}/{file}"
        if folder.endswith("_test") and folder[:-5] in domains:
            return f"{folder[:-5]}/test/{file}"
        return None

    return select


@dataclass(frozen=True)
class DataSet:
    """A reference data set: where it ships, where a reference copy lies, and how to fetch it (if it can be)."""

    name: str
    description: str
    licence: str
    shipped: str | None = None  # folder under data/ holding the shipped subset
    shared: str | None = None  # folder under the reference data ($GSR_SHARED_DATA or ../shared/data)
    package: str | None = None  # fetchable: the package on the index ...
    version: str | None = None
    filename: str | None = None  # ... its release file
    sha256: str | None = None  # ... pinned digest of that file
    files: int = 0  # how many data files the release yields
    licence_member: str | None = None  # the licence file inside the archive
    selector: Callable[[list[str]], Callable[[str], str | None]] | None = None
    provide: str = ""  # how to get a set that cannot be fetched

    @property
    def fetchable(self) -> bool:
        return self.package is not None


SETS: dict[str, DataSet] = {
    s.name: s
    for s in (
        DataSet(
            "libero",
            "LIBERO task files (BDDL): libero_10, libero_90, libero_goal, libero_object, libero_spatial (130)",
            "MIT (Lifelong Robot Learning)",
            shipped="libero",
            shared="libero",
            package="libero",
            version="0.1.1",
            filename="libero-0.1.1.tar.gz",
            sha256="31f17f69ced68e2ecde630353dda924372b0b7b647991e21eade231b241fc373",
            files=130,
            licence_member="libero-0.1.1/LICENSE",
            selector=lambda names: _libero_member,
        ),
        DataSet(
            "behavior",
            "BEHAVIOR-100 activity definitions (BDDL, one problem each) and domain_igibson.bddl (101)",
            "MIT (Stanford Vision and Learning Lab)",
            shipped="behavior",
            shared="behavior",
            package="bddl",
            version="1.0.1",
            filename="bddl-1.0.1.tar.gz",
            sha256="1fa4e6e5050b93888ff6fd8455c39bfb29d3864ce06b4c37c0f781f513a2ae26",
            files=101,
            licence_member="bddl-1.0.1/LICENSE",
            selector=lambda names: _behavior_member,
        ),
        DataSet(
            "pddlgym",
            "PDDLGym's 87 PDDL domains (blocks, gripper, logistics, depot, hanoi, sokoban, ...) with their "
            "train problems (D/*.pddl) and test problems (D/test/*.pddl)",
            "MIT (Tom Silver and Rohan Chitnis)",
            package="pddlgym",
            version="0.0.7",
            filename="pddlgym-0.0.7-py3-none-any.whl",
            sha256="ff601704bef2d27008700e63252d753975a5766409e4e3ba1a9cbfb163252800",
            files=3182,
            licence_member="pddlgym-0.0.7.dist-info/LICENSE.md",
            selector=_pddlgym_members,
        ),
        DataSet(
            "ipc",
            "IPC planning sets (blocks, gripper, miconic-simpleadl and more; domain.pddl + problems)",
            "IPC benchmarks, freely redistributed",
            shared="pddl",
            provide="from github.com/aibasel/downward-benchmarks (set GSR_SHARED_DATA to a folder with pddl/)",
        ),
        DataSet(
            "gsr-bench",
            "the public GSR-Bench task configurations (saved_configs.yaml)",
            "none stated: never copied",
            shared="gsr_bench",
            provide="3Ddesk/saved_configs.yaml of github.com/KLMmotion/GSR-bench; pass --source FILE "
            "(or set GSR_SHARED_DATA to a folder with gsr_bench/saved_configs_dev.yaml)",
        ),
        DataSet(
            "prs",
            "PRS in-building delivery data (maps, people, schedules, tasks)",
            "none stated: never copied",
            shared="prs",
            provide="env/data and task of github.com/PRS-Organization/prs-delivery; pass --source FOLDER "
            "(or set GSR_SHARED_DATA to a folder with prs/)",
        ),
    )
}


def get_set(name: str) -> DataSet:
    """The data set ``name``; a one-line error listing the known ones otherwise."""
    try:
        return SETS[name]
    except KeyError:
        raise GSRError(f"unknown data set {name!r}; known: {', '.join(SETS)}") from None


def fetch_names(names: list[str]) -> list[DataSet]:
    """The sets ``names`` stands for (``all``: every fetchable one), every name checked before any fetch."""
    if not names:
        raise GSRError(
            f"name a data set to fetch: {', '.join(n for n, s in SETS.items() if s.fetchable)} or all"
        )
    out: list[DataSet] = []
    for name in names:
        sets = [s for s in SETS.values() if s.fetchable] if name == "all" else [get_set(name)]
        for s in sets:
            if not s.fetchable:
                raise GSRError(f"data set {s.name!r} cannot be fetched ({s.licence}); get it {s.provide}")
            if s not in out:
                out.append(s)
    return out


# ---------------------------------------------------------------------------------------------- where


def fetched_dir(name: str, cache: Path | None = None) -> Path:
    """Where the fetched copy of ``name`` lives (whether or not it is there)."""
    return (cache or cache_dir()) / name


def manifest(path: Path) -> dict | None:
    """The fetch manifest of a fetched set's folder (None when absent or unreadable)."""
    try:
        data = json.loads((path / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def _complete(ds: DataSet, path: Path) -> bool:
    m = manifest(path)
    return (
        m is not None
        and m.get("package") == ds.package
        and m.get("version") == ds.version
        and m.get("sha256") == ds.sha256
        and m.get("files") == ds.files
    )


@dataclass(frozen=True)
class Copy:
    """One copy of a set: its kind (fetched, reference, shipped) and folder."""

    kind: str
    path: Path


def copies(name: str, cache: Path | None = None) -> list[Copy]:
    """Every copy of ``name`` present, best first: fetched, reference (shared), shipped."""
    ds = get_set(name)
    out: list[Copy] = []
    if ds.fetchable and _complete(ds, fetched_dir(name, cache)):
        out.append(Copy("fetched", fetched_dir(name, cache)))
    if ds.shared is not None and (shared_data_dir() / ds.shared).exists():
        out.append(Copy("reference", shared_data_dir() / ds.shared))
    if ds.shipped is not None:
        try:
            path = data_dir() / ds.shipped
        except GSRError:
            path = None
        if path is not None and path.is_dir():
            out.append(Copy("shipped", path))
    return out


def locate(name: str, cache: Path | None = None) -> Path:
    """The best copy of ``name`` (fetched, reference, shipped); a one-line error naming how to get it."""
    found = copies(name, cache)
    if found:
        return found[0].path
    ds = get_set(name)
    how = f"run `gsr data fetch {name}`" if ds.fetchable else f"get it {ds.provide}"
    raise GSRError(f"data set {name!r} not found: {how}, or pass --source PATH")


def count_files(path: Path) -> int:
    """Data files under a folder (the manifest and licence not counted)."""
    if path.is_file():
        return 1
    skip = {MANIFEST, "LICENSE", "LICENSE.md", "README.md"}
    return sum(1 for p in path.rglob("*") if p.is_file() and p.name not in skip)


# ---------------------------------------------------------------------------------------------- fetch


def index_url() -> str:
    """The package index's JSON API root: ``$GSR_PYPI_URL`` (a mirror, or a file:// folder) or PyPI."""
    return os.environ.get("GSR_PYPI_URL", DEFAULT_INDEX).rstrip("/")


def _open(url: str, what: str):
    try:
        return urllib.request.urlopen(url, timeout=60)
    except urllib.error.HTTPError as exc:
        raise GSRError(f"{what}: the package index answered {exc.code} {exc.reason} for {url}") from None
    except (urllib.error.URLError, OSError, ValueError, http.client.HTTPException) as exc:
        reason = getattr(exc, "reason", None) or exc
        host = urllib.parse.urlsplit(url).netloc or url
        raise GSRError(
            f"{what}: cannot reach the package index ({host}: {reason}); check the network or set GSR_PYPI_URL"
        ) from None


def release_file(ds: DataSet, index: str | None = None) -> tuple[str, int]:
    """The download URL and size of ``ds``'s release file, from the index's JSON API (``PACKAGE/json``,
    its ``releases``); the sha256 the index lists must be the pinned one."""
    url = f"{index or index_url()}/{ds.package}/json"
    with _open(url, ds.name) as resp:
        try:
            meta = json.loads(resp.read().decode("utf-8"))
        except (ValueError, UnicodeDecodeError, OSError, http.client.HTTPException):
            raise GSRError(f"{ds.name}: the package index sent an unreadable answer for {url}") from None
    releases = meta.get("releases") if isinstance(meta, dict) else None
    files = releases.get(ds.version) if isinstance(releases, dict) else None
    entry = next((f for f in files or [] if isinstance(f, dict) and f.get("filename") == ds.filename), None)
    if entry is None or not isinstance(entry.get("url"), str):
        raise GSRError(f"{ds.name}: {ds.package}=={ds.version} on the package index has no {ds.filename}")
    listed = (entry.get("digests") or {}).get("sha256")
    if listed != ds.sha256:
        raise GSRError(
            f"{ds.name}: the package index lists sha256 {listed} for {ds.filename}, expected {ds.sha256}"
        )
    return entry["url"], int(entry.get("size") or 0)


def _download(ds: DataSet, url: str, size: int, dest: Path, progress: Progress | None) -> None:
    digest = hashlib.sha256()
    done = 0
    with _open(url, ds.name) as resp, dest.open("wb") as out:
        total = size or int((getattr(resp, "headers", None) or {}).get("Content-Length") or 0)
        while True:
            try:
                chunk = resp.read(CHUNK)
            except (OSError, http.client.HTTPException) as exc:
                raise GSRError(f"{ds.name}: download of {ds.filename} broke off: {exc!r}") from None
            if not chunk:
                break
            out.write(chunk)
            digest.update(chunk)
            done += len(chunk)
            if progress:
                progress(done, total)
    got = digest.hexdigest()
    if got != ds.sha256:
        raise GSRError(f"{ds.name}: corrupt download of {ds.filename} (sha256 {got}, expected {ds.sha256})")


def _members(archive: Path) -> Iterator[tuple[list[str], Callable[[str], bytes]]]:
    """The member names of a .tar.gz or .whl/.zip and a reader of one member's bytes."""
    if archive.name.endswith((".whl", ".zip")):
        with zipfile.ZipFile(archive) as z:
            yield [i.filename for i in z.infolist() if not i.is_dir()], z.read
        return
    with tarfile.open(archive, "r:*") as t:
        members = {m.name: m for m in t.getmembers() if m.isfile()}

        def read(name: str) -> bytes:
            f = t.extractfile(members[name])
            assert f is not None
            return f.read()

        yield list(members), read


def _extract(ds: DataSet, archive: Path, dest: Path) -> int:
    assert ds.selector is not None
    try:
        for names, read in _members(archive):
            select = ds.selector(names)
            written = 0
            for name in sorted(names):
                rel = select(name)
                if rel is None:
                    continue
                target = dest / rel
                if ".." in Path(rel).parts or target.exists():
                    raise GSRError(f"{ds.name}: {ds.filename} has an unexpected member {name!r}")
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(read(name))
                written += 1
            if ds.licence_member in names:
                (dest / Path(ds.licence_member).name).write_bytes(read(ds.licence_member))
            return written
    except (tarfile.TarError, zipfile.BadZipFile, EOFError, KeyError) as exc:
        raise GSRError(f"{ds.name}: {ds.filename} is not a readable archive ({exc})") from None
    return 0


@dataclass(frozen=True)
class Fetched:
    """The outcome of one fetch: the set, its folder, and whether it was already there."""

    name: str
    path: Path
    files: int
    already: bool


def fetch(
    name: str,
    cache: Path | None = None,
    *,
    force: bool = False,
    progress: Progress | None = None,
    index: str | None = None,
) -> Fetched:
    """Fetch the set ``name`` into the cache (idempotent; ``force`` fetches again).

    The release file is downloaded into a temporary folder inside the cache, its sha256 checked, the
    data files extracted beside it with a manifest, and the finished folder renamed into place: on any
    error (network, corrupt download, full disk) the temporary folder is removed and the cache is as it was.
    """
    ds = next(iter(fetch_names([name])))
    root = cache or cache_dir()
    target = fetched_dir(ds.name, root)
    if not force and _complete(ds, target):
        return Fetched(ds.name, target, ds.files, already=True)
    url, size = release_file(ds, index)
    try:
        root.mkdir(parents=True, exist_ok=True)
        work = Path(tempfile.mkdtemp(prefix=f".fetch-{ds.name}-", dir=root))
    except OSError as exc:
        raise GSRError(f"{ds.name}: cannot write to the cache {root}: {exc.strerror}") from None
    try:
        archive = work / ds.filename
        _download(ds, url, size, archive, progress)
        staged = work / ds.name
        staged.mkdir()
        written = _extract(ds, archive, staged)
        if written != ds.files:
            raise GSRError(f"{ds.name}: {ds.filename} holds {written} data files, expected {ds.files}")
        record = {
            "name": ds.name,
            "package": ds.package,
            "version": ds.version,
            "file": ds.filename,
            "sha256": ds.sha256,
            "url": url,
            "files": written,
            "licence": ds.licence,
        }
        (staged / MANIFEST).write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
        previous = work / "previous"
        if target.exists() or target.is_symlink():
            os.replace(target, previous)
        try:
            os.replace(staged, target)
        except OSError:
            if previous.exists():
                os.replace(previous, target)
            raise
        return Fetched(ds.name, target, written, already=False)
    except OSError as exc:
        why = "no space left on the device" if exc.errno == errno.ENOSPC else (exc.strerror or str(exc))
        raise GSRError(f"{ds.name}: cannot write to the cache {root}: {why}; nothing was written") from None
    finally:
        shutil.rmtree(work, ignore_errors=True)
