"""Peer scan matchers from PyPI, set up fairly for 2D (see ../shared/docs/PEERS.md).

Each peer takes a target (map-frame points) once and then aligns source scans
from an initial SE(2) guess. 2D points are lifted to 3D by extruding them into
three layers (z = -5, 0, +5 cm) so GICP's per-point covariances keep one thin
direction (the wall normal); results are projected back to SE(2) as
``x, y, atan2(R[1, 0], R[0, 0])``. Correspondence gates go coarse to fine. No
downsampling beyond merging points closer than 1 cm.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]

LAYERS = (-0.05, 0.0, 0.05)
MERGE = 0.01  # m: voxel size that only merges near-duplicate points


def lift(points: F64) -> F64:
    """(N, 2) -> (3N, 3) points in three z layers."""
    return np.vstack([np.c_[points, np.full(len(points), z)] for z in LAYERS])


def to_matrix(pose: npt.ArrayLike) -> F64:
    """SE(2) pose [x, y, theta] -> 4x4 homogeneous matrix."""
    x, y, t = np.asarray(pose, dtype=float)
    m = np.eye(4)
    m[:2, :2] = [[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]]
    m[:2, 3] = x, y
    return m


def to_pose(m: F64) -> F64:
    """4x4 matrix -> SE(2) pose [x, y, theta]."""
    return np.array([m[0, 3], m[1, 3], np.arctan2(m[1, 0], m[0, 0])])


@dataclass
class Peer:
    """A named matcher: ``prepare(target_points) -> state``, ``align(state, pts, guess)``."""

    name: str
    prepare: Callable[[F64], Any]
    align: Callable[[Any, F64, F64], F64]


def small_gicp_peers() -> list[Peer]:
    """small_gicp GICP (kd-tree target) and VGICP (Gaussian voxel maps), 1 thread."""
    import small_gicp

    def gicp_prepare(target: F64) -> Any:
        return small_gicp.preprocess_points(lift(target), MERGE, num_neighbors=10)

    def gicp_align(state: Any, pts: F64, guess: F64) -> F64:
        cloud, tree = state
        src, _ = small_gicp.preprocess_points(lift(pts), MERGE, num_neighbors=10)
        t = to_matrix(guess)
        for gate in (1.0, 0.25):
            r = small_gicp.align(
                cloud,
                src,
                tree,
                t,
                registration_type="GICP",
                max_correspondence_distance=gate,
                max_iterations=30,
            )
            t = r.T_target_source
        return to_pose(t)

    def vgicp_prepare(target: F64) -> Any:
        cloud, _ = small_gicp.preprocess_points(lift(target), MERGE, num_neighbors=10)
        maps = []
        for size in (0.5, 0.2):
            vm = small_gicp.GaussianVoxelMap(size)
            vm.insert(cloud)
            maps.append(vm)
        return maps

    def vgicp_align(state: Any, pts: F64, guess: F64) -> F64:
        src, _ = small_gicp.preprocess_points(lift(pts), MERGE, num_neighbors=10)
        t = to_matrix(guess)
        for vm in state:
            r = small_gicp.align(vm, src, t, max_iterations=30)
            t = r.T_target_source
        return to_pose(t)

    return [
        Peer("small_gicp GICP (1.0→0.25 m)", gicp_prepare, gicp_align),
        Peer("small_gicp VGICP (0.5→0.2 m)", vgicp_prepare, vgicp_align),
    ]


def open3d_peers() -> list[Peer]:
    """Open3D ICP point-to-point and point-to-plane, gates 1.0 → 0.25 → 0.1 m."""
    import open3d as o3d

    reg = o3d.pipelines.registration

    def cloud(points: F64, normals: bool) -> Any:
        pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(lift(points)))
        if normals:
            pc.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(10))
        return pc

    def make(plane: bool) -> Peer:
        method = (
            reg.TransformationEstimationPointToPlane()
            if plane
            else reg.TransformationEstimationPointToPoint()
        )

        def prepare(target: F64) -> Any:
            return cloud(target, plane)

        def align(state: Any, pts: F64, guess: F64) -> F64:
            src = cloud(pts, False)
            t = to_matrix(guess)
            for gate in (1.0, 0.25, 0.1):
                t = reg.registration_icp(
                    src, state, gate, t, method, reg.ICPConvergenceCriteria(max_iteration=30)
                ).transformation
            return to_pose(np.asarray(t))

        kind = "point-to-plane" if plane else "point-to-point"
        return Peer(f"Open3D ICP {kind} (1.0→0.1 m)", prepare, align)

    return [make(False), make(True)]


def all_peers() -> list[Peer]:
    """Every peer that imports here (a missing one is reported and skipped)."""
    out: list[Peer] = []
    for factory in (small_gicp_peers, open3d_peers):
        try:
            out.extend(factory())
        except ImportError as exc:
            print(f"peer skipped: {exc}")
    return out
