"""Reading user input files: DEM, Manning roughness, polygons."""
