"""The numerical core: numba kernels on plain arrays and scalars.

Nothing here reads files, logs or knows the scenario: ``floodsph.model.flood_model`` unpacks the
particle set and the terrain and calls these kernels.
"""
