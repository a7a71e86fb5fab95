"""Everything the run reads before the model exists: terrain, roughness, hydrographs, initial
water, vector layers, the memory estimate."""
