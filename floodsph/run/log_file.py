"""The run folder's ``floodsph.log``: floodsph's INFO records, for the length of a run."""

from __future__ import annotations

import logging
from pathlib import Path


def attach_log(path: Path, append: bool = False) -> tuple[logging.Handler, int]:
    """Send floodsph's INFO (and higher) records to ``path`` for the length of the run
    (appended to a resumed run's log).

    Returns the handler and the logger level to restore afterwards.
    """
    handler = logging.FileHandler(path, mode="a" if append else "w", encoding="utf-8")
    handler.setLevel(logging.INFO)
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    logger = logging.getLogger("floodsph")
    previous = logger.level
    if logger.getEffectiveLevel() > logging.INFO:
        logger.setLevel(logging.INFO)
    logger.addHandler(handler)
    return handler, previous


def detach_log(handler: logging.Handler, previous_level: int) -> None:
    """Stop sending records to the run's log file and restore the logger level."""
    logger = logging.getLogger("floodsph")
    logger.removeHandler(handler)
    logger.setLevel(previous_level)
    handler.close()
