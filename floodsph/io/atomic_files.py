"""Files that appear whole or not at all: a temporary name beside the target, then a rename.

``os.replace`` within one folder is atomic on POSIX file systems, so a reader (or a run that
dies half-way) never sees half a file under the target's name. The file is made readable by
the group and others as far as the user's umask allows, as files written by ``open`` are
(``tempfile.mkstemp`` would leave it private, mode 0600).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

#: Temporary names start with this; what a killed run leaves under them is removed later.
TEMP_PREFIX = ".tmp-"


@contextlib.contextmanager
def atomic_path(target: str | Path) -> Iterator[Path]:
    """A temporary path beside ``target``; on success it is renamed onto ``target``.

    On an exception the temporary file is removed, ``target`` is untouched and the exception
    goes on.
    """
    target = Path(target)
    tmp = target.with_name(f"{TEMP_PREFIX}{target.name}")
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~umask())
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
