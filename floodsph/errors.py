"""User-facing error types, and the one way input warnings are reported."""

from __future__ import annotations

import logging

log = logging.getLogger("floodsph.inputs.prepare")


class InputError(Exception):
    """A problem with the user's input (file, key, value), reported as one plain message.

    The command line prints ``str(error)`` without a traceback and exits with status 2. The
    message names the file, the key path (``inflows[0].hydrograph``) or the value at fault.
    """


def warn(message: str, warnings: list[str] | None) -> None:
    """Report an input the user may mean but should look at again.

    The message is logged at WARNING level (logger ``floodsph.inputs.prepare``) and, when
    ``warnings`` is a list, appended to it (``floodsph.inputs.prepare.Inputs.warnings``, which the
    run records in ``run.json``).
    """
    log.warning("%s", message)
    if warnings is not None:
        warnings.append(message)
