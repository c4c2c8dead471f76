"""The stamp the benchmarks put on a run (``benches/datasets.py``): the commit and
whether the work tree has changes, asked of git in the repository."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from tests._benches import load_bench

ds = load_bench("datasets")


def test_outside_a_clone_the_commit_is_unknown_and_nothing_is_changed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(ds, "REPO", tmp_path)
    # git must not find a repository above the temporary directory either.
    monkeypatch.setenv("GIT_CEILING_DIRECTORIES", str(tmp_path.parent))
    assert ds.git("rev-parse", "HEAD") is None
    assert ds.machine().endswith(", commit unknown")
    assert ds.dirty() == ""


@pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")
def test_a_changed_tracked_file_marks_the_stamp(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def run(*args: str) -> None:
        subprocess.run(["git", *args], cwd=tmp_path, check=True, capture_output=True)

    run("init", "-q")
    (tmp_path / "a.txt").write_text("one\n")
    run("add", "a.txt")
    run("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "one")
    monkeypatch.setattr(ds, "REPO", tmp_path)
    head = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"],
        cwd=tmp_path,
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    assert ds.machine().endswith(f", commit {head}")
    assert ds.dirty() == ""
    # An untracked file does not count; a change to a tracked one does.
    (tmp_path / "b.txt").write_text("new\n")
    assert ds.dirty() == ""
    (tmp_path / "a.txt").write_text("two\n")
    assert ds.dirty() == " (+ uncommitted changes)"
