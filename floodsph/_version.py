"""The package version, read by ``floodsph --version`` and written into every run manifest."""

__version__ = "0.1.0"
