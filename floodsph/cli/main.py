"""The ``floodsph`` command group.

Subcommands live one per module in ``floodsph.cli`` (``run.py``, ``check.py``, ...), each
exposing a click command named ``command``. :class:`LazyGroup` imports a command's module only
when that command is used (or listed by ``--help``), and every module imports the library
inside its command function, so ``floodsph --help`` never imports numba, rasterio or xarray
and never compiles anything.

Global options (before the command name):

=================  ==============================================================
``--version``      print the version and exit
``-v/--verbose``   more log output on stderr (``-v`` INFO, ``-vv`` DEBUG)
``-q/--quiet``     errors only, no progress bar
``--threads N``    numba threads (default: the scenario's ``numerics.threads``)
``--debug``        show the traceback of an input error instead of one line
=================  ==============================================================

Errors: a :class:`floodsph.errors.InputError` is printed as one line on stderr and exits with
status 2; any other failure (the simulation, a full disk, ...) is one line and status 1, an
interruption (Ctrl-C, SIGTERM, SIGHUP) status 130. ``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import importlib
import importlib.util
import logging
import os
import sys

import click

from floodsph._version import __version__

COMMANDS = {
    "run": "floodsph.cli.run",
    "check": "floodsph.cli.check",
    "compare": "floodsph.cli.compare",
    "breach": "floodsph.cli.breach",
    "ensemble": "floodsph.cli.ensemble",
}
"""Command name -> module path; each module exposes a click command named ``command``."""

EXIT_INPUT_ERROR = 2
EXIT_FAILED = 1
EXIT_INTERRUPTED = 130


class LazyGroup(click.Group):
    """A click group that imports its subcommands' modules on first use."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(name for name, module in COMMANDS.items() if _exists(module))

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        module = COMMANDS.get(name)
        if module is None or not _exists(module):
            return None
        return importlib.import_module(module).command

    def invoke(self, ctx: click.Context):
        """Run the subcommand; turn input errors into one line and exit status 2."""
        from floodsph.errors import InputError

        debug = bool(ctx.params.get("debug"))
        try:
            return super().invoke(ctx)
        except InputError as exc:
            if debug:
                raise
            click.echo(f"Error: {exc}", err=True)
            ctx.exit(EXIT_INPUT_ERROR)
        except KeyboardInterrupt as exc:
            click.echo(f"Interrupted{': ' + str(exc) if str(exc) else ''}.", err=True)
            ctx.exit(EXIT_INTERRUPTED)
        except Exception as exc:
            if debug or isinstance(exc, click.ClickException | click.exceptions.Exit
                                             | click.Abort):
                raise
            from floodsph.run.pipeline import error_message

            click.echo(f"Error: {error_message(exc)}", err=True)
            ctx.exit(EXIT_FAILED)


def _exists(module: str) -> bool:
    return importlib.util.find_spec(module) is not None


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="floodsph", message="%(prog)s %(version)s")
@click.option("-v", "--verbose", count=True, help="More log output (-v INFO, -vv DEBUG).")
@click.option("-q", "--quiet", is_flag=True, help="Only errors; no progress bar.")
@click.option(
    "--threads",
    type=click.IntRange(min=0),
    default=None,
    help="Number of numba threads (0 = all cores; default: the scenario's numerics.threads).",
)
@click.option("--debug", is_flag=True, help="Show tracebacks of input errors.")
@click.pass_context
def cli(ctx: click.Context, verbose: int, quiet: bool, threads: int | None, debug: bool):
    """floodsph: dam-breach flood maps on real terrain with shallow-water SPH."""
    ctx.ensure_object(dict)
    ctx.obj.update(verbose=verbose, quiet=quiet, threads=threads, debug=debug)
    if threads and "numba" not in sys.modules:
        # numba reads NUMBA_NUM_THREADS once, at import: set it before any command imports it.
        os.environ["NUMBA_NUM_THREADS"] = str(threads)
    _configure_logging(verbose, quiet)


def _configure_logging(verbose: int, quiet: bool) -> None:
    """A stderr handler on the ``floodsph`` logger at the level the flags ask for."""
    level = logging.ERROR if quiet else {0: logging.WARNING, 1: logging.INFO}.get(
        verbose, logging.DEBUG
    )
    logger = logging.getLogger("floodsph")
    for handler in list(logger.handlers):
        if getattr(handler, "_floodsph_console", False):
            logger.removeHandler(handler)
    handler = logging.StreamHandler()
    handler._floodsph_console = True  # type: ignore[attr-defined]  # our handler's mark
    handler.addFilter(lambda record: not getattr(record, "file_only", False))
    handler.setLevel(level)
    handler.setFormatter(logging.Formatter("%(levelname)s: %(message)s"))
    logger.addHandler(handler)
    logger.setLevel(min(level, logging.INFO))
    logging.captureWarnings(True)
