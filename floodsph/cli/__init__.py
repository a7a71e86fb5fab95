"""The ``floodsph`` command line: one module per command, loaded on demand (see ``main``)."""
