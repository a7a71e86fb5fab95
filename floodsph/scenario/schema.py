"""Typed readers for the scenario TOML: every check names the file and the key path.

The scenario reader (``floodsph.scenario.reader``) reads each table through these helpers so that
every problem is reported the same way, before any work starts::

    scenario.toml: inflows[0].line: expected two [x, y] points, got 1

A :class:`Reader` carries the file name (as the user gave it) and the folder that relative
paths are resolved against. Key paths are built as ``table.key`` and ``array[i].key``.
"""

from __future__ import annotations

import math
import tomllib
from datetime import datetime
from enum import Enum
from pathlib import Path
from typing import Any, TypeVar, overload

from floodsph.checks.shapes import polygon_problem, polyline_problem
from floodsph.constants import LARGEST_VALUE
from floodsph.errors import InputError

#: Marks a key without a default: absent means "missing required key".
REQUIRED: Any = object()

E = TypeVar("E", bound=Enum)


def read_toml(path: Path, what: str) -> dict:
    """The parsed TOML file ``path``, or one InputError naming it: missing (``what`` file not
    found), invalid TOML (with line and column) or unreadable."""
    source = str(path)
    if not path.is_file():
        raise InputError(f"{source}: {what} file not found")
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{source}: invalid TOML: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{source}: cannot read the {what} file: {exc}") from None


def join(path: str, key: str | int) -> str:
    """The key path of ``key`` inside ``path`` (``terrain`` + ``dem`` -> ``terrain.dem``)."""
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else key


def describe(value: Any) -> str:
    """A short description of a TOML value's type and value, for error messages."""
    kind = {
        bool: "boolean",
        int: "integer",
        float: "number",
        str: "string",
        list: "array",
        dict: "table",
    }.get(type(value), type(value).__name__)
    text = repr(value)
    if len(text) > 40:
        text = text[:37] + "..."
    return f"{kind} {text}" if kind != "table" else "a table"


def is_number(value: Any) -> bool:
    """True for TOML integers and floats (booleans are not numbers here)."""
    return isinstance(value, int | float) and not isinstance(value, bool)


class Reader:
    """Reads values out of a parsed TOML document, raising :class:`InputError` on problems.

    Parameters
    ----------
    source : str
        The scenario file name as shown in messages.
    base_dir : Path
        Folder against which relative paths are resolved (the scenario file's folder).
    """

    def __init__(self, source: str, base_dir: Path):
        self.source = source
        self.base_dir = base_dir

    def fail(self, path: str, message: str) -> InputError:
        """The error to raise for ``path``: ``<file>: <path>: <message>``."""
        where = f"{self.source}: {path}: " if path else f"{self.source}: "
        return InputError(where + message)

    # -- structure ------------------------------------------------------------------------
    def table(self, value: Any, path: str) -> dict:
        if not isinstance(value, dict):
            raise self.fail(path, f"expected a table, got {describe(value)}")
        return value

    def check_keys(self, table: dict, path: str, allowed: tuple[str, ...]) -> None:
        """Reject keys of ``table`` that are not in ``allowed``, listing the allowed ones."""
        for key in table:
            if key not in allowed:
                raise self.fail(
                    join(path, key), f"unknown key; allowed keys: {', '.join(sorted(allowed))}"
                )

    def sub_table(self, table: dict, path: str, key: str, allowed: tuple[str, ...]) -> dict:
        """An optional sub-table (``{}`` when absent), with its keys checked."""
        value = self.table(table.get(key, {}), join(path, key))
        self.check_keys(value, join(path, key), allowed)
        return value

    def table_array(self, table: dict, key: str) -> list[dict]:
        """An optional array of tables (``[[inflows]]``); ``[]`` when absent."""
        value = table.get(key, [])
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            raise self.fail(key, f"expected an array of tables [[{key}]], got {describe(value)}")
        return value

    def _get(self, table: dict, path: str, key: str, default: Any) -> Any:
        if key not in table:
            if default is REQUIRED:
                raise self.fail(join(path, key), "required key is missing")
            return default
        return table[key]

    # -- scalars --------------------------------------------------------------------------
    # A read with ``default=None`` may give None; a required one, or one with a number as its
    # default, gives a number.
    @overload
    def number(self, table: dict, path: str, key: str, default: None, *,
               gt: float | None = None, ge: float | None = None,
               le: float | None = None) -> float | None: ...

    @overload
    def number(self, table: dict, path: str, key: str, default: float = ..., *,
               gt: float | None = None, ge: float | None = None,
               le: float | None = None) -> float: ...

    def number(
        self,
        table: dict,
        path: str,
        key: str,
        default: Any = REQUIRED,
        *,
        gt: float | None = None,
        ge: float | None = None,
        le: float | None = None,
    ) -> float | None:
        """A finite number (integer or float) with optional bounds ``gt``/``ge``/``le``."""
        value = self._get(table, path, key, default)
        if value is default and key not in table:
            return value
        where = join(path, key)
        if not is_number(value):
            raise self.fail(where, f"expected a number, got {describe(value)}")
        value = float(value)
        if not math.isfinite(value):
            raise self.fail(where, f"expected a finite number, got {value}")
        if abs(value) > LARGEST_VALUE:
            raise self.fail(where, f"{value:g} is beyond +-{LARGEST_VALUE:g}, more than any "
                                   "quantity of a flood scenario in SI units")
        if gt is not None and not value > gt:
            raise self.fail(where, f"must be > {gt:g}, got {value:g}")
        if ge is not None and not value >= ge:
            raise self.fail(where, f"must be >= {ge:g}, got {value:g}")
        if le is not None and not value <= le:
            raise self.fail(where, f"must be <= {le:g}, got {value:g}")
        return value

    def integer(self, table: dict, path: str, key: str, default: Any = REQUIRED, *, ge=None,
                le=None):
        """An integer with optional bounds."""
        value = self._get(table, path, key, default)
        if value is default and key not in table:
            return value
        where = join(path, key)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(where, f"expected an integer, got {describe(value)}")
        if abs(value) > LARGEST_VALUE:
            raise self.fail(where, f"{value:g} is beyond +-{LARGEST_VALUE:g}")
        if ge is not None and value < ge:
            raise self.fail(where, f"must be >= {ge}, got {value}")
        if le is not None and value > le:
            raise self.fail(where, f"must be <= {le}, got {value}")
        return value

    @overload
    def string(self, table: dict, path: str, key: str, default: None) -> str | None: ...

    @overload
    def string(self, table: dict, path: str, key: str, default: str = ...) -> str: ...

    def string(self, table: dict, path: str, key: str, default: Any = REQUIRED) -> str | None:
        value = self._get(table, path, key, default)
        if value is default and key not in table:
            return value
        if not isinstance(value, str):
            raise self.fail(join(path, key), f"expected a string, got {describe(value)}")
        if "\0" in value:
            raise self.fail(join(path, key), f"contains a NUL character: {value!r}")
        return value

    def instant(self, table: dict, path: str, key: str) -> datetime | None:
        """An ISO 8601 instant with its time zone: a TOML offset date-time
        (``2024-01-15T06:00:00Z``) or a string of one; None when absent. A date-time without a
        time zone is refused (it could be any of 26 hours)."""
        if key not in table:
            return None
        value, where = table[key], join(path, key)
        if isinstance(value, str):
            try:
                value = datetime.fromisoformat(value.strip())
            except ValueError:
                raise self.fail(where, f"{value!r} is not an ISO 8601 date-time such as "
                                       f"2024-01-15T06:00:00Z") from None
        if not isinstance(value, datetime):
            raise self.fail(where, f"expected a date-time with its time zone such as "
                                   f"2024-01-15T06:00:00Z, got {describe(value)}")
        if value.tzinfo is None or value.utcoffset() is None:
            raise self.fail(where, f"{value.isoformat()} has no time zone; add Z for UTC or "
                                   f"the offset of local time, e.g. {value.isoformat()}Z or "
                                   f"{value.isoformat()}+01:00")
        return value

    def choice(self, table: dict, path: str, key: str, enum: type[E], default: E) -> E:
        """One of the values of ``enum`` (given as its string value)."""
        value = self.string(table, path, key, default.value)
        return self.as_choice(value, join(path, key), enum)

    def as_choice(self, value: Any, path: str, enum: type[E]) -> E:
        allowed = [member.value for member in enum]
        if not isinstance(value, str) or value not in allowed:
            raise self.fail(
                path, f"expected one of {', '.join(map(repr, allowed))}, got {describe(value)}"
            )
        return enum(value)

    # -- files ----------------------------------------------------------------------------
    def resolve(self, value: str, where: str = "") -> Path:
        """``value`` as an absolute path, relative ones taken from the scenario's folder; a
        NUL character (which no file name may hold) is refused naming ``where``."""
        if "\0" in value:
            raise self.fail(where, f"a path cannot contain a NUL character, got {value!r}")
        path = Path(value).expanduser()
        if not path.is_absolute():
            path = self.base_dir / path
        return path.resolve()

    def existing_file(self, table: dict, path: str, key: str, default: Any = REQUIRED):
        """A path to an existing file (resolved), or ``default`` when the key is absent."""
        value = self.string(table, path, key, default)
        if value is default and key not in table:
            return value
        return self.file_value(value, join(path, key))

    def file_value(self, value: str, path: str) -> Path:
        resolved = self.resolve(value, path)
        if not resolved.exists():
            raise self.fail(path, f"file not found: {resolved}")
        if not resolved.is_file():
            raise self.fail(path, f"not a file: {resolved}")
        return resolved

    def vector_source(self, table: dict, path: str, inline: str | None) -> dict:
        """``file`` (+ ``layer``, ``crs``): geometry from a vector file, as keyword arguments
        of the scenario entry (``{}`` without ``file``). ``inline`` names the key it replaces
        (``polyline``, ``polygon``); both together are refused, as is a text table (a
        ``.csv`` file: :mod:`floodsph.io.vector`) and a ``crs`` pyproj cannot read.
        """
        from floodsph.io.vector import VECTOR_FORMATS, is_vector_file

        if "file" not in table:
            for key in ("layer", "crs"):
                if key in table:
                    raise self.fail(join(path, key), "applies only with file (a vector file)")
            return {}
        if inline is not None and inline in table:
            raise self.fail(path, f"give either {inline} or file, not both")
        file = self.existing_file(table, path, "file")
        if not is_vector_file(file):
            raise self.fail(join(path, "file"), f"{file.name}: not a vector file but a text "
                                                f"table; expected a vector file "
                                                f"({VECTOR_FORMATS})")
        crs = self.string(table, path, "crs", None)
        if crs is not None:
            import pyproj

            try:
                pyproj.CRS.from_user_input(crs)
            except pyproj.exceptions.CRSError:
                raise self.fail(join(path, "crs"), f"{crs!r} is not a coordinate reference "
                                                   "system pyproj knows") from None
        out = {"file": file, "layer": self.string(table, path, "layer", None), "crs": crs}
        return {k: v for k, v in out.items() if v is not None}

    # -- geometry -------------------------------------------------------------------------
    def point(self, value: Any, path: str) -> tuple[float, float]:
        """One ``[x, y]`` pair of finite numbers."""
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(path, f"expected an [x, y] pair of numbers, got {describe(value)}")
        for k, c in enumerate(value):
            if not is_number(c) or not math.isfinite(float(c)):
                raise self.fail(join(path, k), f"expected a finite number, got {describe(c)}")
            if abs(c) > LARGEST_VALUE:
                raise self.fail(join(path, k), f"{c:g} is beyond +-{LARGEST_VALUE:g}, no "
                                               "coordinate of a projected CRS")
        return float(value[0]), float(value[1])

    def points(
        self, table: dict, path: str, key: str, *, at_least: int, exactly: int | None = None
    ) -> tuple[tuple[float, float], ...]:
        """A list of ``[x, y]`` points (``exactly`` or ``at_least`` of them)."""
        where = join(path, key)
        value = self._get(table, path, key, REQUIRED)
        if not isinstance(value, list):
            raise self.fail(where, f"expected an array of [x, y] points, got {describe(value)}")
        count = len(value)
        if exactly is not None and count != exactly:
            words = {2: "two", 3: "three"}
            raise self.fail(
                where, f"expected {words.get(exactly, exactly)} [x, y] points, got {count}"
            )
        if count < at_least:
            raise self.fail(where, f"expected at least {at_least} [x, y] points, got {count}")
        return tuple(self.point(p, join(where, k)) for k, p in enumerate(value))

    def polygon(self, table: dict, path: str, key: str) -> tuple[tuple[float, float], ...]:
        """A polygon: at least three distinct points enclosing a non-zero area, its outline not
        crossing itself (:func:`floodsph.checks.shapes.polygon_problem`)."""
        pts = self.points(table, path, key, at_least=3)
        problem = polygon_problem(pts)
        if problem is not None:
            raise self.fail(join(path, key), problem)
        return pts

    def polyline(self, table: dict, path: str, key: str) -> tuple[tuple[float, float], ...]:
        """A wall: at least two distinct points, not crossing itself; a closed one (first ==
        last) a valid polygon (:func:`floodsph.checks.shapes.polyline_problem`)."""
        pts = self.points(table, path, key, at_least=2)
        problem = polyline_problem(pts)
        if problem is not None:
            raise self.fail(join(path, key), problem)
        return pts
