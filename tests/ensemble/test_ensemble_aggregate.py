"""Streamed aggregation over member maps written as GeoTIFFs, the DEM mask, cluster sizing.

Five synthetic members on a 6 x 4 grid, aggregated in blocks of one row (BLOCK_BYTES made
tiny), against numpy on the maps read back from the files, and against values worked out by
hand for cells where dry members count as 0 and arrival needs half the members wet.
"""

from __future__ import annotations

import numpy as np
import pytest

from floodsph.ensemble import aggregate as agg
from floodsph.ensemble.engine import plan_workers
from floodsph.errors import InputError
from floodsph.model.terrain import Terrain
from floodsph.output.geotiff import write_geotiff
from floodsph.output.grid import OutputGrid

NX, NY, MEMBERS = 6, 4, 5
THRESHOLDS = (0.1, 0.5)
QUANTILES = (0.05, 0.5, 0.95)


def grid(nx=NX, ny=NY, dx=10.0) -> OutputGrid:
    from rasterio.crs import CRS

    return OutputGrid(nx, ny, dx, dx, 500_000.0, 4_000_000.0, CRS.from_epsg(32632).to_wkt(),
                      np.zeros((ny, nx)))


def member_maps(rng) -> list[dict]:
    """South-up maps of each member; cell (0, 0) and (0, 1) set by hand (module docstring)."""
    out = []
    for m in range(MEMBERS):
        depth = rng.uniform(0.0, 1.0, (NY, NX))
        depth[rng.random((NY, NX)) < 0.3] = np.nan
        arrival = np.where(np.isnan(depth), np.nan, rng.uniform(0.0, 100.0, (NY, NX)))
        depth[0, 0] = (np.nan, np.nan, np.nan, 0.3, 1.2)[m]
        arrival[0, 0] = (np.nan, np.nan, np.nan, 30.0, 10.0)[m]
        arrival[0, 1] = (np.nan, np.nan, 10.0, 20.0, 30.0)[m]
        speed = np.where(np.isnan(depth), np.nan, rng.uniform(0.0, 3.0, (NY, NX)))
        hazard = np.where(np.isnan(depth), 0, rng.integers(1, 5, (NY, NX))).astype(np.uint8)
        out.append({"max_depth": depth, "max_speed": speed, "arrival_time": arrival,
                    "hazard_uk": hazard})
    return out


@pytest.fixture
def members(tmp_path):
    g = grid()
    folders = []
    for m, maps in enumerate(member_maps(np.random.default_rng(11))):
        folder = tmp_path / f"m{m:04d}"
        folder.mkdir()
        for name, array in maps.items():
            write_geotiff(folder / f"{name}.tif", array, g, name, "1")
        folders.append(folder)
    return g, folders


def read_stack(folders, name):
    import rasterio

    stack = []
    for folder in folders:
        with rasterio.open(folder / f"{name}.tif") as src:
            stack.append(src.read(1)[::-1].astype(np.float64))
    return np.array(stack)


@pytest.fixture
def result(members, tmp_path, monkeypatch):
    g, folders = members
    monkeypatch.setattr(agg, "BLOCK_BYTES", MEMBERS * NX * 8)  # one row per block
    inside = np.ones(g.shape, dtype=bool)
    inside[3, 5] = False
    return agg.aggregate(folders, g, inside, THRESHOLDS, QUANTILES, tmp_path)


def test_maps_equal_numpy_on_the_member_files(members, result):
    _, folders = members
    depth = np.nan_to_num(read_stack(folders, "max_depth"))
    speed = np.nan_to_num(read_stack(folders, "max_speed"))
    hazard = read_stack(folders, "hazard_uk")
    arrival = read_stack(folders, "arrival_time")
    outside = np.zeros((NY, NX), dtype=bool)
    outside[3, 5] = True

    def masked(a):
        a = np.array(a, dtype=np.float64)
        a[..., outside] = np.nan
        return a

    np.testing.assert_allclose(result.p_depth_gt, masked([(depth > t).sum(0) / MEMBERS
                                                          for t in THRESHOLDS]))
    np.testing.assert_allclose(result.max_depth_q, masked(np.quantile(depth, QUANTILES, 0)),
                               rtol=1e-6)
    np.testing.assert_allclose(result.max_speed_q, masked(np.quantile(speed, QUANTILES, 0)),
                               rtol=1e-6)
    np.testing.assert_allclose(result.p_hazard_uk_ge, masked([(hazard >= k).sum(0) / MEMBERS
                                                              for k in (1, 2, 3, 4)]))
    expected = np.full((len(QUANTILES), NY, NX), np.nan)
    for i in range(NY):
        for j in range(NX):
            wet = arrival[:, i, j][np.isfinite(arrival[:, i, j])]
            if 2 * len(wet) >= MEMBERS and not outside[i, j]:
                expected[:, i, j] = np.quantile(wet, QUANTILES)
    np.testing.assert_allclose(result.arrival_time_q, expected, rtol=1e-6)
    assert result.members == MEMBERS


def test_dry_members_count_as_zero_depth(result):
    """Depths (dry, dry, dry, 0.3, 1.2): P(> 0.1 m) = 2/5 and the median is 0, not 0.75."""
    assert result.p_depth_gt[:, 0, 0] == pytest.approx([0.4, 0.2])
    assert result.max_depth_q[1, 0, 0] == 0.0


def test_arrival_needs_half_the_members_wet(result):
    assert np.isnan(result.arrival_time_q[:, 0, 0]).all()  # 2 of 5 wet
    assert result.arrival_time_q[1, 0, 1] == pytest.approx(20.0)  # median of 10, 20, 30


def test_cells_outside_the_dem_are_nan(result):
    for maps in (result.p_depth_gt, result.max_depth_q, result.arrival_time_q,
                 result.p_hazard_uk_ge):
        assert np.isnan(maps[:, 3, 5]).all()


def test_a_member_on_another_grid_is_named(members, tmp_path):
    g, folders = members
    write_geotiff(folders[2] / "max_speed.tif", np.zeros((NY, NX + 1)), grid(nx=NX + 1),
                  "max_speed", "m s-1")
    with pytest.raises(InputError, match=r"m0002/max_speed.tif: the map is on a grid of 7 x 4"):
        agg.aggregate(folders, g, np.ones(g.shape, bool), THRESHOLDS, QUANTILES, tmp_path)
    assert not list(tmp_path.glob(".stacks-*"))


def test_dem_mask_on_a_coarser_map_grid():
    """A 20 m map cell is inside the DEM when its centre's 10 m DEM cell has data."""
    valid = np.ones((6, 8), dtype=bool)
    valid[1, 3] = False  # the centre of 20 m cell (0, 1) lies in DEM cell (1, 3)
    valid[0, 0] = False  # not a 20 m cell centre: cell (0, 0) has its centre in (1, 1)
    terrain = Terrain(np.zeros((6, 8)), 10.0, 10.0, valid=valid)
    mask = agg.dem_mask(terrain, grid(nx=4, ny=3, dx=20.0))
    assert mask.shape == (3, 4)
    assert not mask[0, 1]
    assert mask.sum() == 11


@pytest.mark.parametrize(
    ("args", "plan"),
    [
        ((32, 2, 10**9, 10**10), (2, 1)),  # cores limit: one member per core
        ((32, 8, 10**9, 3 * 10**9), (3, 2)),  # memory fits 3; the 8 cores shared among them
        ((1, 4, 10**9, 10**10), (1, 4)),  # one member gets every core
        ((32, 8, 10**9, None), (8, 1)),  # memory unknown: the cores decide
    ],
)
def test_cluster_size_from_cores_and_memory(args, plan):
    p = plan_workers(*args)
    assert (p.workers, p.threads_per_worker) == plan


def test_cluster_size_with_threads_or_workers_given():
    assert plan_workers(32, 8, 10**9, 10**11, threads=2).workers == 4
    assert plan_workers(32, 8, 10**9, 10**11, workers=3).threads_per_worker == 2


def test_map_files_and_no_picture_without_matplotlib(result, tmp_path, monkeypatch):
    """The contract's file names; without matplotlib the picture is skipped, saying why."""
    from floodsph.ensemble.outputs import write_outputs
    from floodsph.output import pictures

    monkeypatch.setattr(pictures, "have_matplotlib", lambda: False)
    out = tmp_path / "maps"
    out.mkdir()
    written = write_outputs(result, grid(), out, ensemble={"name": "e"}, scenario={},
                            wet_threshold=0.01, title="e")
    assert written.pictures == "pictures skipped: matplotlib not installed"
    assert sorted(written.maps) == sorted(p.name for p in out.iterdir())
    assert set(written.maps) == {
        "p_depth_gt_0.1m.tif", "p_depth_gt_0.5m.tif",
        *(f"{m}_{q}.tif" for m in ("max_depth", "max_speed", "arrival_time")
          for q in ("q05", "q50", "q95")),
        *(f"p_hazard_uk_ge_{k}.tif" for k in (1, 2, 3, 4)), "ensemble_maps.nc"}
