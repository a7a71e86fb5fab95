"""Generate the synthetic ``valley`` sample: a reservoir, a dam gorge and a valley below it.

Writes ``valley/dem.tif`` (EPSG:32632, 10 m cells, 3 km x 1.5 km, float32, deflate) and
``valley/gauges.csv``. Run from anywhere: ``python data_samples/make_valley.py``. Needs only
numpy and rasterio; the output is deterministic.

The ground is built in coordinates ``s`` (metres down the valley from the west edge) and
``r`` (metres across it from the meandering centreline):

* thalweg  z_t(s) = Z_TOP - SLOPE s, plus a steep rise at the head of the reservoir;
* floor    z_t + FLOOR_SLOPE |r| inside the half-width W(s), side slopes SIDE_SLOPE beyond;
* the reservoir basin is a bowl BASIN_DEPTH deep over s < DAM_S (no dam body: the instant
  total failure removed it, the scenario's level + polygon put the lake back at t = 0);
* at the dam line DAM_S the valley narrows to a gorge, then widens into a floodplain with a
  river channel and a town on a low terrace.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import rasterio
from rasterio.transform import from_origin

OUT = Path(__file__).resolve().parent / "valley"

X_WEST, Y_SOUTH = 342_000.0, 5_061_000.0  # EPSG:32632 (WGS 84 / UTM 32N), lower-left corner
CELL = 10.0
NX, NY = 300, 150  # 3.0 km east x 1.5 km north

Z_TOP = 232.0  # thalweg elevation at the west edge [m]
SLOPE = 0.007  # valley gradient downstream [-]
FLOOR_SLOPE = 0.004  # cross slope of the valley floor [-]
SIDE_SLOPE = 0.18  # valley side slopes [-]
DAM_S = 900.0  # dam line, metres from the west edge
BASIN_DEPTH = 6.0  # depth of the reservoir bowl below the thalweg [m]
LEVEL = 234.0  # reservoir level used by scenario.toml [m]
TOWN = (2150.0, 2450.0, -230.0, -70.0)  # s-range and r-range of the town terrace
TOWN_RAISE = 1.0  # terrace height above the floor [m]


def smoothstep(a: float, b: float, s: np.ndarray) -> np.ndarray:
    """0 below a, 1 above b, C1 cubic in between."""
    t = np.clip((s - a) / (b - a), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def centreline(s: np.ndarray) -> np.ndarray:
    """Northing of the valley axis above the south edge [m]: straight, then meandering."""
    return 750.0 + 90.0 * smoothstep(DAM_S, DAM_S + 400.0, s) * np.sin(
        2.0 * np.pi * (s - DAM_S) / 1400.0
    )


def half_width(s: np.ndarray) -> np.ndarray:
    """Half-width of the flat floor [m]: reservoir 180, gorge 40, floodplain 260."""
    reservoir = 140.0 * (1.0 - smoothstep(DAM_S - 250.0, DAM_S - 20.0, s))
    plain = 260.0 * smoothstep(DAM_S + 60.0, DAM_S + 600.0, s)
    return 40.0 + reservoir + plain


def elevation(s: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Bed elevation [m] at distance ``s`` down the valley and northing ``y`` (from south)."""
    r = y - centreline(s)
    w = half_width(s)
    a = np.abs(r)
    z = Z_TOP - SLOPE * s + FLOOR_SLOPE * a + SIDE_SLOPE * np.maximum(a - w, 0.0)
    z += 30.0 * smoothstep(0.0, 1.0, (200.0 - s) / 200.0) ** 2  # head of the reservoir
    bowl_s = np.sin(np.pi * np.clip((s - 100.0) / (DAM_S - 100.0), 0.0, 1.0)) ** 0.6
    z -= BASIN_DEPTH * bowl_s * np.clip(1.0 - (r / (w + 60.0)) ** 2, 0.0, 1.0)
    channel = smoothstep(DAM_S - 50.0, DAM_S + 100.0, s)
    z -= 2.5 * channel * np.exp(-((r / 12.0) ** 2))
    s0, s1, r0, r1 = TOWN
    pad = smoothstep(s0 - 40, s0, s) * (1 - smoothstep(s1, s1 + 40, s))
    pad *= smoothstep(r0 - 30, r0, r) * (1 - smoothstep(r1, r1 + 30, r))
    return z + TOWN_RAISE * pad


def main() -> None:
    OUT.mkdir(exist_ok=True)
    s = (np.arange(NX) + 0.5) * CELL
    y = (np.arange(NY) + 0.5) * CELL
    S, Yn = np.meshgrid(s, y[::-1])  # north-up rows
    z = elevation(S, Yn).astype(np.float32)
    profile = dict(
        driver="GTiff",
        width=NX,
        height=NY,
        count=1,
        dtype="float32",
        crs="EPSG:32632",
        transform=from_origin(X_WEST, Y_SOUTH + NY * CELL, CELL, CELL),
        nodata=-9999.0,
        compress="deflate",
        predictor=3,
    )
    with rasterio.open(OUT / "dem.tif", "w", **profile) as dst:
        dst.write(z, 1)
        dst.set_band_description(1, "bed elevation [m]")
        dst.update_tags(1, units="m")

    gauge_s = [1000.0, 1500.0, 2000.0, 2300.0, 2800.0]
    with open(OUT / "gauges.csv", "w") as fh:
        fh.write("id,x,y\n")
        for k, gs in enumerate(gauge_s, start=1):
            gy = float(centreline(np.array(gs)))
            fh.write(f"G{k},{X_WEST + gs:.1f},{Y_SOUTH + gy:.1f}\n")

    wet = (S < DAM_S) & (z < LEVEL)
    volume = float(np.sum(LEVEL - z[wet]) * CELL**2)
    print(f"wrote {OUT}: {NX}x{NY} cells, z {z.min():.1f}..{z.max():.1f} m")
    print(f"reservoir at {LEVEL} m: {wet.sum()} cells, {volume / 1e6:.2f} Mm3")


if __name__ == "__main__":
    main()
