"""``python -m floodsph``: the ``floodsph`` command."""

from floodsph.cli.main import cli

cli(prog_name="floodsph")
