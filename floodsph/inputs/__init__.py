"""Everything the run reads before the model exists: the terrain (``floodsph.inputs.dem``),
initial water, vector layers, the checked and prepared inputs, the memory estimate. The
file readers it uses (rasters, roughness, hydrographs) are ``floodsph.io``."""
