"""``benchmarks/malpasset/anuga_malpasset.py`` without ANUGA: the mesh and its grid mapping.

ANUGA needs every triangle's vertices anticlockwise (positive signed area
(b - a) x (c - a) / 2); its maxima are per triangle and go onto the DEM grid through the
triangle holding each cell centre, NaN where no triangle holds it. On the benchmark data
(skipped when absent) the TELEMAC mesh converted to EPSG:27572 keeps a positive area for all
26 000 triangles, and every one of the 29 survey points lies inside it (the ANUGA gauges are
the triangles holding them).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import load_script

pytestmark = pytest.mark.benchmark

REPO = Path(__file__).resolve().parents[2]
amp = load_script("anuga_malpasset", REPO / "benchmarks" / "malpasset" / "anuga_malpasset.py")
mp_setup = load_script("malpasset_setup", REPO / "benchmarks" / "malpasset" /
                         "malpasset_setup.py")

DATA = mp_setup.data_folder()
needs_malpasset = pytest.mark.skipif(
    DATA is None, reason="Malpasset benchmark data not found (set FLOODSPH_BENCHMARKS)")


def signed_areas(nodes: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    a, b, c = (nodes[triangles[:, k]] for k in range(3))
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
                  - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def test_clockwise_triangles_are_turned_anticlockwise_on_the_same_vertices():
    nodes = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    triangles = np.array([[0, 1, 2], [0, 3, 2]])  # anticlockwise, clockwise
    out = amp.counter_clockwise(nodes, triangles)
    assert np.all(signed_areas(nodes, out) > 0)
    assert np.array_equal(out[0], triangles[0])
    assert [sorted(t) for t in out] == [sorted(t) for t in triangles]


def test_cells_take_the_value_of_the_triangle_holding_their_centre_and_nan_outside():
    # Two triangles over the square [0, 20] x [0, 20]; a 3 x 3 grid of 10 m cells over
    # [0, 30] x [0, 30]: the centres at x or y = 25 m lie outside the mesh.
    nodes = np.array([[0.0, 0.0], [20.0, 0.0], [20.0, 20.0], [0.0, 20.0]])
    triangles = np.array([[0, 1, 2], [0, 2, 3]])  # below and above the diagonal y = x
    xc, yc = np.meshgrid([5.0, 15.0, 25.0], [5.0, 15.0, 25.0])
    cell_tri = amp.triangle_of_points(nodes, triangles, xc.ravel(), yc.ravel())
    grid = amp.on_grid(np.array([1.0, 2.0]), cell_tri, (3, 3))
    assert np.isnan(grid[2]).all() and np.isnan(grid[:, 2]).all()
    assert grid[0, 1] == 1.0 and grid[1, 0] == 2.0  # (15, 5) below, (5, 15) above


@needs_malpasset
def test_benchmark_mesh_is_anticlockwise_and_holds_every_survey_point():
    nodes, triangles = amp.read_mesh(DATA)
    triangles = amp.counter_clockwise(nodes, triangles)
    assert len(triangles) == 26000
    assert np.all(signed_areas(nodes, triangles) > 0)
    points = mp_setup.read_points(DATA)
    assert len(points) == 29
    found = amp.triangle_of_points(nodes, triangles, [p["x"] for p in points],
                                   [p["y"] for p in points])
    assert np.all(found >= 0)
