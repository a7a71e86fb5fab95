"""Files and coordinates at the lowest level: rasters, vectors, text tables, hydrograph CSVs,
Manning roughness and its checks, polygons, the CRS of inline coordinates, the names of a run
folder's files and atomic writes. Nothing here imports another floodsph package but
``floodsph.errors`` and ``floodsph.constants``; the DEM becomes a ``Terrain`` in
``floodsph.inputs.dem``."""
