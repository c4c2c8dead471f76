"""Match a scan against a 2 cm NDT map: the README's example, runnable as is."""

import numpy as np

import ndtgrid
from ndtgrid import se2

# Points on the walls of a 4 m x 3 m room with a box in it, in the map frame.
t = np.linspace(0.0, 1.0, 300)[:, None]
corners = [(-2, -1.5), (2, -1.5), (2, 1.5), (-2, 1.5), (-2, -1.5)]
walls = [(corners[i], corners[i + 1]) for i in range(4)] + [((0.5, 0.2), (1.2, 0.9))]
room = np.vstack([(1 - t) * np.array(a) + t * np.array(b) for a, b in walls])

grid = ndtgrid.NdtGrid(cell_size=0.02)  # the paper's 2 cm cells
grid.insert(room, [0.0, 0.0, 0.0])  # eq. (6): the map, seen from the origin

true_pose = np.array([0.03, -0.02, np.radians(1.0)])  # where the robot really is
inv = se2.inverse(true_pose)  # the same walls, seen from there:
c, s = np.cos(inv[2]), np.sin(inv[2])
scan = room @ np.array([[c, s], [-s, c]]) + inv[:2]

result = grid.match(scan, [0.0, 0.0, 0.0])  # start from "no motion"
print(result)
print(
    "error [mm, deg]:",
    np.round(1e3 * np.hypot(*(result.pose - true_pose)[:2]), 3),
    np.round(np.degrees(result.pose[2] - true_pose[2]), 4),
)
