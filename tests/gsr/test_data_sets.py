"""gsr data fetch / list / path against a local fake package index (no network): checksums, atomic
writes, idempotence, and one-line errors for unknown names, unreachable indexes, corrupt downloads and
full disks."""

from __future__ import annotations

import dataclasses
import errno
import hashlib
import io
import json
import re
import tarfile
import zipfile
from pathlib import Path

import pytest
from typer.testing import CliRunner

from gsr import data_sets
from gsr.cli import app
from gsr.data_sets import SETS, copies, fetch, fetch_names, locate
from gsr.errors import GSRError

BOWL = "(define (problem p) (:domain robosuite) (:objects a - bowl) (:init) (:goal (and)))\n"


def _tar(path: Path, members: dict[str, bytes]) -> bytes:
    with tarfile.open(path, "w:gz") as t:
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            t.addfile(info, io.BytesIO(data))
    return path.read_bytes()


class FakeIndex:
    """A file:// package index with one release file per registered set."""

    def __init__(self, root: Path, monkeypatch: pytest.MonkeyPatch) -> None:
        self.root = root
        self.monkeypatch = monkeypatch
        monkeypatch.setenv("GSR_PYPI_URL", (root / "index").as_uri())

    def publish(self, name: str, filename: str, data: bytes, files: int, listed: str | None = None) -> None:
        ds = SETS[name]
        (self.root / "files").mkdir(parents=True, exist_ok=True)
        path = self.root / "files" / filename
        path.write_bytes(data)
        digest = hashlib.sha256(data).hexdigest()
        meta = {
            "releases": {
                ds.version: [
                    {
                        "filename": filename,
                        "url": path.as_uri(),
                        "size": len(data),
                        "digests": {"sha256": listed or digest},
                    }
                ]
            }
        }
        folder = self.root / "index" / ds.package
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "json").write_text(json.dumps(meta))
        pinned = dataclasses.replace(ds, filename=filename, sha256=listed or digest, files=files)
        self.monkeypatch.setitem(SETS, name, pinned)


def _libero_archive(tmp: Path, tasks: int = 3) -> bytes:
    members = {"libero-0.1.1/LICENSE": b"MIT License\n", "libero-0.1.1/setup.py": b"print()\n"}
    for k in range(tasks):
        members[f"libero-0.1.1/libero/libero/bddl_files/libero_goal/task_{k}.bddl"] = BOWL.encode()
    members["libero-0.1.1/libero/libero/bddl_files/libero_goal/notes.txt"] = b"not a task"
    return _tar(tmp / "src.tar.gz", members)


@pytest.fixture
def index(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> FakeIndex:
    monkeypatch.setenv("GSR_CACHE", str(tmp_path / "cache"))
    return FakeIndex(tmp_path, monkeypatch)


def _leftovers(cache: Path) -> list[str]:
    return sorted(p.name for p in cache.iterdir()) if cache.exists() else []


def test_fetch_extracts_checks_and_is_idempotent(index: FakeIndex, tmp_path: Path) -> None:
    index.publish("libero", "libero-0.1.1.tar.gz", _libero_archive(tmp_path), files=3)
    cache = tmp_path / "cache"
    got = fetch("libero")
    assert not got.already and got.files == 3 and got.path == cache / "libero"
    assert sorted(p.name for p in (cache / "libero" / "libero_goal").iterdir()) == [
        "task_0.bddl",
        "task_1.bddl",
        "task_2.bddl",
    ]
    assert (cache / "libero" / "LICENSE").read_text() == "MIT License\n"
    manifest = json.loads((cache / "libero" / ".gsr-data.json").read_text())
    assert manifest["version"] == "0.1.1" and manifest["files"] == 3
    assert _leftovers(cache) == ["libero"]  # the temporary folder is gone
    stamp = (cache / "libero" / "libero_goal" / "task_0.bddl").stat().st_mtime_ns
    again = fetch("libero")
    assert again.already and (cache / "libero" / "libero_goal" / "task_0.bddl").stat().st_mtime_ns == stamp
    assert locate("libero") == cache / "libero"
    assert copies("libero")[0].kind == "fetched"
    forced = fetch("libero", force=True)
    assert not forced.already and _leftovers(cache) == ["libero"]


def test_fetch_a_wheel(index: FakeIndex, tmp_path: Path) -> None:
    buf = tmp_path / "w.whl"
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("pddlgym-0.0.7.dist-info/LICENSE.md", "MIT License\n")
        z.writestr("pddlgym/pddl/hanoi.pddl", "(define (domain hanoi))")
        z.writestr("pddlgym/pddl/hanoi/problem1.pddl", "(define (problem h1) (:domain hanoi))")
        z.writestr("pddlgym/pddl/hanoi_test/problem9.pddl", "(define (problem h9) (:domain hanoi))")
        z.writestr("pddlgym/pddl/orphan_test/problem1.pddl", "(define (problem o))")  # no domain: left out
        z.writestr("pddlgym/core.py", "")
    index.publish("pddlgym", "pddlgym-0.0.7-py3-none-any.whl", buf.read_bytes(), files=3)
    got = fetch("pddlgym")
    files = sorted(str(p.relative_to(got.path)) for p in got.path.rglob("*.pddl"))
    assert files == ["hanoi/domain.pddl", "hanoi/problem1.pddl", "hanoi/test/problem9.pddl"]
    assert (got.path / "LICENSE.md").is_file()


def test_corrupt_download_writes_nothing(index: FakeIndex, tmp_path: Path) -> None:
    data = _libero_archive(tmp_path)
    index.publish("libero", "libero-0.1.1.tar.gz", data, files=3)
    (tmp_path / "files" / "libero-0.1.1.tar.gz").write_bytes(data[:-10] + b"0123456789")  # bytes changed
    with pytest.raises(GSRError, match=r"libero: corrupt download of libero-0.1.1.tar.gz \(sha256 "):
        fetch("libero")
    assert _leftovers(tmp_path / "cache") == []


def test_index_listing_another_checksum_is_refused(index: FakeIndex, tmp_path: Path) -> None:
    index.publish("libero", "libero-0.1.1.tar.gz", _libero_archive(tmp_path), files=3)
    SETS["libero"] = dataclasses.replace(SETS["libero"], sha256="0" * 64)  # the pin differs
    with pytest.raises(GSRError, match="the package index lists sha256"):
        fetch("libero")
    assert _leftovers(tmp_path / "cache") == []


def test_unexpected_file_count_and_unreadable_archive(index: FakeIndex, tmp_path: Path) -> None:
    index.publish("libero", "libero-0.1.1.tar.gz", _libero_archive(tmp_path, tasks=2), files=3)
    with pytest.raises(GSRError, match="holds 2 data files, expected 3"):
        fetch("libero")
    index.publish("libero", "libero-0.1.1.tar.gz", b"not a gzip file at all", files=3)
    with pytest.raises(GSRError, match="is not a readable archive"):
        fetch("libero")
    assert _leftovers(tmp_path / "cache") == []


def test_unreachable_index_is_one_line(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GSR_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("GSR_PYPI_URL", (tmp_path / "nowhere").as_uri())
    with pytest.raises(GSRError, match="cannot reach the package index") as info:
        fetch("libero")
    assert "\n" not in str(info.value)
    assert _leftovers(tmp_path / "cache") == []


def test_download_broken_off_writes_nothing(index: FakeIndex, tmp_path: Path, monkeypatch) -> None:
    import http.client
    import urllib.request

    index.publish("libero", "libero-0.1.1.tar.gz", _libero_archive(tmp_path), files=3)
    real = urllib.request.urlopen

    class Broken(io.BytesIO):
        headers = None  # no Content-Length: the index gave the size

        def read(self, n: int = -1) -> bytes:
            raise http.client.IncompleteRead(b"partial", 100)

    def urlopen(url: str, timeout: float = 0):
        return Broken() if url.endswith(".tar.gz") else real(url, timeout=timeout)

    monkeypatch.setattr(urllib.request, "urlopen", urlopen)
    with pytest.raises(GSRError, match=r"libero: download of libero-0\.1\.1\.tar\.gz broke off"):
        fetch("libero")
    assert _leftovers(tmp_path / "cache") == []


def test_full_disk_leaves_the_old_copy(index: FakeIndex, tmp_path: Path, monkeypatch) -> None:
    index.publish("libero", "libero-0.1.1.tar.gz", _libero_archive(tmp_path), files=3)
    fetch("libero")
    before = sorted(p.name for p in (tmp_path / "cache" / "libero").rglob("*"))
    real = Path.write_bytes

    def full(self: Path, data: bytes) -> int:
        if self.suffix == ".bddl":
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, data)

    monkeypatch.setattr(Path, "write_bytes", full)
    with pytest.raises(GSRError, match="no space left on the device; nothing was written"):
        fetch("libero", force=True)
    assert _leftovers(tmp_path / "cache") == ["libero"]
    assert sorted(p.name for p in (tmp_path / "cache" / "libero").rglob("*")) == before


def test_names_are_checked_before_anything_is_fetched() -> None:
    with pytest.raises(GSRError, match=r"unknown data set 'nosuch'; known: libero, behavior, pddlgym"):
        fetch_names(["libero", "nosuch"])
    with pytest.raises(GSRError, match="'gsr-bench' cannot be fetched"):
        fetch_names(["gsr-bench"])
    assert [s.name for s in fetch_names(["all", "libero"])] == ["libero", "behavior", "pddlgym"]


def test_locate_falls_back_to_the_shipped_copy(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("GSR_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("GSR_SHARED_DATA", str(tmp_path / "no-reference"))
    assert locate("libero").parts[-2:] == ("data", "libero")
    assert len(list(locate("libero").glob("*/*.bddl"))) == 40
    with pytest.raises(GSRError, match="run `gsr data fetch pddlgym`"):
        locate("pddlgym")
    with pytest.raises(GSRError, match="KLMmotion/GSR-bench"):
        locate("gsr-bench")


def test_cli_fetch_list_path_and_errors(index: FakeIndex, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("GSR_SHARED_DATA", str(tmp_path / "no-reference"))
    index.publish("libero", "libero-0.1.1.tar.gz", _libero_archive(tmp_path), files=3)
    runner = CliRunner()
    first = runner.invoke(app, ["data", "fetch", "libero"])
    assert first.exit_code == 0, first.output
    assert "libero: fetched libero==0.1.1 (sha256 ok): 3 files" in first.output
    assert "already present" in runner.invoke(app, ["data", "fetch", "libero"]).output
    listed = runner.invoke(app, ["data", "list"]).output
    assert re.search(rf"fetched +3 files +{re.escape(str(tmp_path / 'cache' / 'libero'))}\n", listed)
    assert re.search(r"shipped +40 files", listed) and "gsr data fetch pddlgym" in listed
    path = runner.invoke(app, ["data", "path", "libero"])
    assert path.output.strip() == str(tmp_path / "cache" / "libero")
    bad = runner.invoke(app, ["data", "fetch", "nosuch"])
    assert bad.exit_code != 0 and "unknown data set 'nosuch'" in str(bad.exception)


def test_shipped_sets_match_their_declared_counts() -> None:
    """The repository copies named in data/README.md: 40 LIBERO files and 5 BEHAVIOR activities, with licences."""
    root = Path(data_sets.data_dir())
    assert len(list((root / "libero").glob("*/*.bddl"))) == 40
    assert len(list((root / "behavior").glob("*.bddl"))) == 6
    for folder in ("libero", "behavior"):
        assert (root / folder / "LICENSE").read_text().startswith("MIT License")
    readme = (root / "README.md").read_text()
    assert "libero==0.1.1" in readme and "bddl==1.0.1" in readme
