"""floodsph: dam-breach flood mapping on real terrain with shallow-water SPH.

The package import is deliberately light (no numba, no rasterio) so that the command line
answers ``--help`` at once; import the submodules you need.
"""

from floodsph._version import __version__

__all__ = ["__version__"]
