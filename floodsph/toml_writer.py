"""A small TOML writer for plain data (the resolved scenario copy).

Handles what ``Scenario.to_dict()`` produces: tables, arrays of tables (``[[inflows]]``),
sub-tables inside them (``[inflows.breach]``), strings, booleans, integers, floats and
(nested) arrays of those. ``None`` values are skipped (TOML has no null). Strings are written
as TOML basic strings; JSON escaping is a subset of TOML's, so ``json.dumps`` does it.
"""

from __future__ import annotations

import json
import math


def dumps(data: dict) -> str:
    """``data`` (a dict of plain values) as a TOML document."""
    lines: list[str] = []
    _table(data, [], lines)
    return "\n".join(lines).strip() + "\n"


def _is_table(value) -> bool:
    return isinstance(value, dict)


def _is_table_array(value) -> bool:
    return isinstance(value, list) and len(value) > 0 and all(isinstance(v, dict) for v in value)


def _key(key: str) -> str:
    bare = key.replace("_", "").replace("-", "").isalnum() and key.isascii()
    return key if bare else json.dumps(key)


def _value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} as a TOML value")


def _table(data: dict, path: list[str], lines: list[str]) -> None:
    """Scalars of ``data`` first (TOML requires it), then its sub-tables and table arrays."""
    for key, value in data.items():
        if value is None or _is_table(value) or _is_table_array(value):
            continue
        lines.append(f"{_key(key)} = {_value(value)}")
    for key, value in data.items():
        sub = path + [_key(key)]
        if _is_table(value):
            lines.extend(["", f"[{'.'.join(sub)}]"])
            _table(value, sub, lines)
        elif _is_table_array(value):
            for item in value:
                lines.extend(["", f"[[{'.'.join(sub)}]]"])
                _table(item, sub, lines)
