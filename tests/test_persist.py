"""Saving, loading and pickling maps (docs/API.md, "persistence").

``NdtGrid`` / ``Mapper``: ``save``, ``load``, ``to_bytes``, ``from_bytes`` and pickle
(also in another process) give back the map bit for bit, and a loaded mapper goes on
exactly as the saved one. The records the library returns (a match's result, an
odometry step, small objects, removal counts, mapper options) pickle and copy by value.
Errors have exact messages (``ValueError`` for a bad file, ``OSError`` naming the file
for I/O); writes are atomic; every truncation and seeded
byte flips are rejected. The large corruption runs are the Rust tests'
(crates/ndt-core/tests/persist.rs); these are smaller runs through the binding.
"""

from __future__ import annotations

import copy
import os
import pickle
import struct
import subprocess
import sys
import zlib
from concurrent.futures import ProcessPoolExecutor
from functools import lru_cache
from multiprocessing import get_context
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import ndtgrid
from ndtgrid import sim

from ._room import scan as room_scan

HEADER = 28
MAGIC_MESSAGE = 'not an ndtgrid file (it does not start with the magic bytes "NDTGRID\\0")'


@lru_cache(maxsize=1)
def walk() -> tuple[np.ndarray, list[tuple[np.ndarray, np.ndarray]]]:
    """40 URG-04LX scans along the sticks room's tour (sticks: small objects)."""
    room = sim.sticks_room()
    poses = sim.trajectory(room.tour[:3], step=0.05)[:40]
    return poses, [sim.URG04LX.scan(room, p, k) for k, p in enumerate(poses)]


def feed(mapper: ndtgrid.Mapper, lo: int, hi: int) -> None:
    poses, scans = walk()
    for k in range(lo, hi):
        mapper.insert_scan(scans[k][0], scans[k][1], poses[k])


def room_grid(cell_size: float = 0.02, levels: int = 6, n: int = 3) -> ndtgrid.NdtGrid:
    grid = ndtgrid.NdtGrid(cell_size, levels=levels)
    for k in range(n):
        pose = [0.1 * k, -0.05 * k, 0.05 * k]
        grid.insert(room_scan(pose, noise=0.005, seed=k), pose)
    return grid


def states(grid: ndtgrid.NdtGrid) -> list[bytes]:
    """The exact cell state as raw bytes (bit-identical comparison, NaN and -0 included)."""
    return [a.tobytes() for a in grid.cell_states()]


def mapper_state(m: ndtgrid.Mapper) -> tuple[Any, ...]:
    """Everything observable of a mapper, and its bytes (its whole state)."""
    return (
        m.to_bytes(),
        states(m.grid),
        m.occupied_cells().tobytes(),
        m.removal_counts().as_dict(),
        m.scan_count,
        [(o.center.tobytes(), o.cells.tobytes(), o.num_points) for o in m.small_objects()],
        m.options,
    )


def match_state(grid: ndtgrid.NdtGrid) -> list[tuple[bytes, float, int, bytes]]:
    out = []
    for k, guess in enumerate([[0.03, -0.02, 0.02], [0.25, 0.0, 0.05]]):
        pts = room_scan([0.05, -0.02, 0.03], noise=0.005, seed=10 + k)
        r = grid.match(pts, guess)
        out.append((r.pose.tobytes(), r.score, r.iterations, r.covariance.tobytes()))
    return out


# --- round trips ---------------------------------------------------------------------------


def test_grid_save_and_load_are_bit_identical(tmp_path: Path) -> None:
    grid = room_grid(levels=4)
    path = tmp_path / "room.ndtgrid"
    grid.save(path)
    back = ndtgrid.NdtGrid.load(path)
    assert isinstance(back, ndtgrid.NdtGrid)
    assert (back.cell_size, back.levels, len(back)) == (0.02, 4, len(grid))
    assert states(back) == states(grid)
    assert path.read_bytes() == grid.to_bytes() == back.to_bytes()
    assert match_state(back) == match_state(grid)
    # str paths and from_bytes too.
    assert states(ndtgrid.NdtGrid.load(str(path))) == states(grid)
    assert states(ndtgrid.NdtGrid.from_bytes(grid.to_bytes())) == states(grid)
    empty = ndtgrid.NdtGrid(0.1, levels=1)
    again = ndtgrid.NdtGrid.from_bytes(empty.to_bytes())
    assert (again.cell_size, again.levels, len(again)) == (0.1, 1, 0)


def test_a_loaded_mapper_goes_on_exactly_as_the_saved_one(tmp_path: Path) -> None:
    original = ndtgrid.Mapper(0.02)
    feed(original, 0, 20)
    path = tmp_path / "mapper.ndtgrid"
    original.save(path)
    loaded = ndtgrid.Mapper.load(path)
    assert mapper_state(loaded) == mapper_state(original)
    feed(original, 20, 40)
    feed(loaded, 20, 40)
    assert mapper_state(loaded) == mapper_state(original)
    assert loaded.scan_count == 40 and len(loaded.small_objects()) > 0
    assert sum(original.removal_counts().as_dict().values()) > 0
    # The loaded mapper's grid is its own map, shared with mapper.grid as always.
    assert len(loaded.grid) == len(loaded)


def test_options_survive_the_round_trip() -> None:
    m = ndtgrid.Mapper(0.05, reliable_range=0.8, check_interval=5, max_range=5.5)
    back = ndtgrid.Mapper.from_bytes(m.to_bytes())
    assert back.options == m.options and back.cell_size == 0.05
    unfiltered = ndtgrid.Mapper(outlier_filter=False)
    assert not ndtgrid.Mapper.from_bytes(unfiltered.to_bytes()).options.outlier_filter


# --- pickle ----------------------------------------------------------------------------------


def test_pickle_and_copy_use_the_file_format() -> None:
    grid = room_grid()
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        back = pickle.loads(pickle.dumps(grid, protocol=protocol))
        assert states(back) == states(grid) and back.levels == grid.levels
    assert grid.to_bytes() in pickle.dumps(grid, protocol=5)
    assert states(copy.deepcopy(grid)) == states(copy.copy(grid)) == states(grid)
    mapper = ndtgrid.Mapper(0.02)
    feed(mapper, 0, 6)
    twin = pickle.loads(pickle.dumps(mapper))
    assert mapper_state(twin) == mapper_state(mapper)
    # A copy, not a view: the twin's grid is its own.
    feed(twin, 6, 7)
    assert twin.scan_count == 7 and mapper.scan_count == 6
    # mapper.grid pickles as a plain grid.
    assert states(pickle.loads(pickle.dumps(mapper.grid))) == states(mapper.grid)


CHILD = """
import pickle, sys
grid, mapper, scans, poses = pickle.load(sys.stdin.buffer)
for (r, a, _), p in zip(scans, poses):
    mapper.insert_scan(r, a, p)
res = grid.match(scans[0][2], [0.03, -0.02, 0.02])
pickle.dump((mapper, grid, res.pose, res.score), sys.stdout.buffer)
"""


def child_env() -> dict[str, str]:
    """This process's environment, with this ndtgrid first on the path."""
    here = str(Path(ndtgrid.__file__).resolve().parents[1])
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([here, env.get("PYTHONPATH", "")])
    return env


def test_pickles_cross_process_boundaries() -> None:
    grid = room_grid()
    mapper = ndtgrid.Mapper(0.02)
    feed(mapper, 0, 10)
    poses, scans = walk()
    pts = room_scan([0.05, -0.02, 0.03], noise=0.005, seed=3)
    job = (grid, mapper, [(r, a, pts) for r, a in scans[10:16]], poses[10:16])
    out = subprocess.run(
        [sys.executable, "-c", CHILD],
        input=pickle.dumps(job),
        capture_output=True,
        check=True,
        env=child_env(),
    ).stdout
    their_mapper, their_grid, pose, score = pickle.loads(out)
    feed(mapper, 10, 16)
    mine = grid.match(pts, [0.03, -0.02, 0.02])
    assert mapper_state(their_mapper) == mapper_state(mapper)
    assert states(their_grid) == states(grid)
    assert pose.tobytes() == mine.pose.tobytes() and score == mine.score


def _grow(mapper: ndtgrid.Mapper, lo: int, hi: int) -> ndtgrid.Mapper:
    """Worker of the multiprocessing test: insert scans ``lo..hi``, send the mapper back."""
    feed(mapper, lo, hi)
    return mapper


def test_pickles_go_through_a_multiprocessing_pool() -> None:
    mapper = ndtgrid.Mapper(0.02)
    feed(mapper, 0, 8)
    with ProcessPoolExecutor(max_workers=1, mp_context=get_context("spawn")) as pool:
        theirs = pool.submit(_grow, mapper, 8, 12).result(timeout=120)
    feed(mapper, 8, 12)
    assert mapper_state(theirs) == mapper_state(mapper)


def fields(record: Any) -> dict[str, Any]:
    """Every public attribute of a record, arrays as their dtype, shape and bytes."""
    out = {}
    for name in dir(record):
        value = getattr(record, name)
        if name.startswith("_") or callable(value):
            continue
        if isinstance(value, np.ndarray):
            value = (value.dtype.str, value.shape, value.tobytes())
        out[name] = value
    return out


def records() -> list[Any]:
    """One of each record the library returns: a match's result, an odometry step, a
    small object, the §V removal counts and the mapper's options."""
    mapper = ndtgrid.Mapper(0.02)
    feed(mapper, 0, 40)
    objects = mapper.small_objects()
    assert objects, "the sticks room's walk finds small objects"
    odometry = ndtgrid.Odometry()
    poses, scans = walk()
    for k in range(3):
        odometry.step(scans[k][0], scans[k][1], poses[k])
    grid = room_grid()
    result = grid.match(room_scan([0.05, -0.02, 0.03], noise=0.005, seed=10), [0.03, 0, 0])
    counts = mapper.removal_counts()
    assert any(counts.as_dict().values())
    return [result, odometry.last_step, objects[0], counts, mapper.options]


def test_records_pickle_and_copy_by_value() -> None:
    """Every protocol, ``copy`` and ``deepcopy`` give back every field bit for bit (a
    record is immutable, so equal fields are an equal record)."""
    for record in records():
        want = fields(record)
        assert len(want) >= 3, type(record).__name__
        copies = [copy.copy(record), copy.deepcopy(record)]
        copies += [pickle.loads(pickle.dumps(record, protocol=p)) for p in range(6)]
        for back in copies:
            assert type(back) is type(record)
            assert fields(back) == want, type(record).__name__
            assert repr(back) == repr(record)


def _match_in_worker(grid: ndtgrid.NdtGrid, points: np.ndarray, guess: list[float]) -> Any:
    return grid.match(points, guess)


def test_match_results_come_back_from_a_process_pool() -> None:
    """A match run in a worker process returns its result to the caller."""
    grid = room_grid()
    points = room_scan([0.05, -0.02, 0.03], noise=0.005, seed=10)
    with ProcessPoolExecutor(max_workers=1, mp_context=get_context("spawn")) as pool:
        theirs = pool.submit(_match_in_worker, grid, points, [0.03, 0.0, 0.0]).result(120)
    assert fields(theirs) == fields(grid.match(points, [0.03, 0.0, 0.0]))


# --- errors --------------------------------------------------------------------------------


def with_version(data: bytes, version: int) -> bytes:
    """``data`` with another format version and a checksum that is right again."""
    head = data[:12] + struct.pack("<I", version) + data[16:24]
    crc = zlib.crc32(head + data[HEADER:])
    return head + struct.pack("<I", crc) + data[HEADER:]


def test_bad_bytes_give_exact_messages() -> None:
    grid = room_grid(0.05, n=1)
    data = grid.to_bytes()
    n = len(data)
    cases: list[tuple[Any, bytes, str]] = [
        (ndtgrid.NdtGrid, b"PK\x03\x04" + bytes(40), MAGIC_MESSAGE),
        (
            ndtgrid.Mapper,
            data,
            "wrong kind of ndtgrid file: expected a mapper file, got a grid file",
        ),
        (
            ndtgrid.NdtGrid,
            ndtgrid.Mapper(0.05).to_bytes(),
            "wrong kind of ndtgrid file: expected a grid file, got a mapper file",
        ),
        (
            ndtgrid.NdtGrid,
            with_version(data, ndtgrid._core.FORMAT_VERSION + 1),
            "unsupported ndtgrid file version 2: this build reads version 1",
        ),
        (ndtgrid.NdtGrid, data[:-1], f"truncated ndtgrid file: expected {n} bytes, got {n - 1}"),
        (ndtgrid.NdtGrid, data[:10], "truncated ndtgrid file: expected 28 bytes, got 10"),
        (ndtgrid.NdtGrid, b"", "truncated ndtgrid file: expected 28 bytes, got 0"),
        (
            ndtgrid.NdtGrid,
            data + b"\0",
            f"ndtgrid file has 1 unexpected bytes after its payload: expected {n} bytes, "
            f"got {n + 1}",
        ),
    ]
    flipped = bytearray(data)
    flipped[n // 2] ^= 0x01
    stored = struct.unpack("<I", data[24:28])[0]
    computed = zlib.crc32(bytes(flipped[:24]) + bytes(flipped[HEADER:]))
    cases.append(
        (
            ndtgrid.NdtGrid,
            bytes(flipped),
            f"corrupt ndtgrid file: checksum mismatch (stored {stored:#010x}, "
            f"computed {computed:#010x})",
        )
    )
    assert ndtgrid._core.FORMAT_VERSION == 1
    for cls, bad, message in cases:
        with pytest.raises(ValueError) as info:
            cls.from_bytes(bad)
        assert str(info.value) == message
    with pytest.raises(TypeError):
        ndtgrid.NdtGrid.from_bytes("NDTGRID")  # type: ignore[arg-type]


def test_bad_files_name_the_file(tmp_path: Path) -> None:
    missing = tmp_path / "missing.ndtgrid"
    with pytest.raises(FileNotFoundError) as info:
        ndtgrid.NdtGrid.load(missing)
    assert info.value.errno == 2 and info.value.filename == str(missing)
    assert (
        str(info.value) == f"[Errno 2] cannot read the file: No such file or directory: '{missing}'"
    )
    with pytest.raises(IsADirectoryError) as dir_info:
        ndtgrid.Mapper.load(tmp_path)
    assert dir_info.value.filename == str(tmp_path)
    assert "cannot read the file: Is a directory" in str(dir_info.value)
    grid_file = tmp_path / "grid.ndtgrid"
    room_grid(0.05, n=1).save(grid_file)
    with pytest.raises(ValueError) as bad:
        ndtgrid.Mapper.load(grid_file)
    assert str(bad.value) == (
        f"{grid_file}: wrong kind of ndtgrid file: expected a mapper file, got a grid file"
    )
    text = tmp_path / "notes.txt"
    text.write_text("hello")
    with pytest.raises(ValueError) as bad:
        ndtgrid.NdtGrid.load(text)
    assert str(bad.value) == f"{text}: {MAGIC_MESSAGE}"
    with pytest.raises(TypeError):
        ndtgrid.NdtGrid.load(3)  # type: ignore[arg-type]


# --- atomic writes ---------------------------------------------------------------------------


def test_saving_replaces_the_old_file_whole_and_leaves_nothing_else(tmp_path: Path) -> None:
    path = tmp_path / "map.ndtgrid"
    big = ndtgrid.Mapper(0.02)
    feed(big, 0, 5)
    big.save(path)
    small = room_grid(0.1, n=1)
    small.save(path)
    assert path.read_bytes() == small.to_bytes()
    assert sorted(os.listdir(tmp_path)) == ["map.ndtgrid"]
    assert (path.stat().st_mode & 0o044) == 0o044  # not a temporary file's 0o600


def test_failed_saves_leave_the_old_file_and_no_temporary_file(tmp_path: Path) -> None:
    grid = room_grid(0.05, n=1)
    orphan = tmp_path / "no-such-dir" / "map.ndtgrid"
    with pytest.raises(FileNotFoundError) as info:
        grid.save(orphan)
    assert info.value.filename == str(orphan)
    assert "cannot create a temporary file beside it" in str(info.value)
    taken = tmp_path / "taken"
    taken.mkdir()
    (taken / "keep").write_bytes(b"keep")
    with pytest.raises(OSError) as info:
        grid.save(taken)
    assert info.value.filename == str(taken)
    assert "cannot replace the file" in str(info.value)
    assert os.listdir(taken) == ["keep"] and sorted(os.listdir(tmp_path)) == ["taken"]


WRITER = """
import resource, signal, sys
import ndtgrid
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
grid = ndtgrid.NdtGrid.from_bytes(sys.stdin.buffer.read())
try:
    grid.save(sys.argv[1])
except OSError as exc:
    print(type(exc).__name__, exc.errno, exc.filename)
"""


@pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_FSIZE / SIGXFSZ as on Linux")
def test_a_save_that_fails_mid_write_keeps_the_old_file(tmp_path: Path) -> None:
    # The file-size limit makes the write fail after 4 KiB (EFBIG): the old file must stay
    # as it was and the half-written temporary file must go.
    path = tmp_path / "map.ndtgrid"
    old = room_grid(0.2, n=1)
    old.save(path)
    new = room_grid(0.02, n=3)
    assert len(new.to_bytes()) > 4096
    out = subprocess.run(
        [sys.executable, "-c", WRITER, str(path)],
        input=new.to_bytes(),
        capture_output=True,
        check=True,
        env=child_env(),
    ).stdout.decode()
    assert out.split() == ["OSError", "27", str(path)]
    assert path.read_bytes() == old.to_bytes()
    assert os.listdir(tmp_path) == ["map.ndtgrid"]


@pytest.mark.skipif(
    not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root ignores directory modes"
)
def test_a_read_only_directory_refuses_the_save(tmp_path: Path) -> None:
    path = tmp_path / "map.ndtgrid"
    old = room_grid(0.2, n=1)
    old.save(path)
    tmp_path.chmod(0o555)
    try:
        with pytest.raises(PermissionError):
            room_grid(0.05, n=1).save(path)
    finally:
        tmp_path.chmod(0o755)
    assert path.read_bytes() == old.to_bytes() and os.listdir(tmp_path) == ["map.ndtgrid"]


# --- corruption ------------------------------------------------------------------------------


def saved_maps() -> list[tuple[Any, bytes]]:
    grid = room_grid(0.05, n=2)
    mapper = ndtgrid.Mapper(0.05)
    feed(mapper, 0, 4)
    assert 200 <= len(grid) <= 1000 and 200 <= len(mapper) <= 2000
    return [(ndtgrid.NdtGrid, grid.to_bytes()), (ndtgrid.Mapper, mapper.to_bytes())]


def test_every_truncation_is_rejected() -> None:
    for cls, data in saved_maps():
        for length in range(len(data)):
            with pytest.raises(ValueError, match=r"^truncated ndtgrid file: expected"):
                cls.from_bytes(data[:length])


def test_seeded_byte_flips_are_rejected_or_load_the_same_map() -> None:
    rng = np.random.default_rng(2026)
    for cls, data in saved_maps():
        rejected = 0
        for _ in range(1000):
            bad = bytearray(data)
            for _ in range(int(rng.integers(1, 5))):
                bad[int(rng.integers(len(bad)))] ^= int(rng.integers(1, 256))
            try:
                loaded = cls.from_bytes(bytes(bad))
            except ValueError:
                rejected += 1
            else:  # only flips that cancel out may load, and then to the same map
                assert bytes(bad) == data and loaded.to_bytes() == data
        assert rejected >= 990
