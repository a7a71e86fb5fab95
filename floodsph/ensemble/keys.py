"""Key paths into a scenario, spelled as the scenario's own messages spell them.

A key path is a chain of table keys and array indices, ``terrain.manning``,
``initial_water[0].level_m``, ``inflows[0].breach.average_width_m`` or
``inflows[0].direction[1]`` (``floodsph.scenario.schema.join`` builds the same strings). It is
looked up in the resolved base scenario (``Scenario.to_dict()``: absolute paths, defaults
filled):

* every table and array entry on the way must exist in the base scenario;
* the last key must be a key that the scenario accepts in its table; it may be absent from the
  base scenario (a key left to its default, e.g. a breach's ``average_width_m``), then
  :func:`lookup` returns :data:`MISSING`;
* it must name a value, not a table.

:func:`base_value` is the value a ``mode = "factor"`` multiplies: the base scenario's value,
or for a parametric breach the default the breach model implies (the Froehlich 2008 average
width and formation time, or the breach table's fixed defaults).
"""

from __future__ import annotations

import copy
import re
from dataclasses import dataclass, fields

from floodsph.scenario.schema import join

#: Returned by :func:`lookup` for a key the scenario accepts but the base scenario leaves out.
MISSING = object()

_NAME = r"[A-Za-z_][A-Za-z0-9_]*"
_KEY = re.compile(rf"^{_NAME}(\.{_NAME}|\[\d+\])*$")
_TOKEN = re.compile(rf"\.?({_NAME})|\[(\d+)\]")


class KeyPathError(ValueError):
    """A key path that does not name a value of the base scenario (message: why)."""


@dataclass(frozen=True)
class KeyPath:
    """A parsed key path: its text and its tokens (table keys as str, indices as int)."""

    text: str
    tokens: tuple[str | int, ...]

    @classmethod
    def parse(cls, text: str) -> KeyPath:
        """Parse ``terrain.manning`` or ``inflows[0].breach.width_m``; KeyPathError if bad."""
        if not isinstance(text, str) or not _KEY.match(text):
            raise KeyPathError(
                f"{text!r} is not a key path (expected keys joined by '.' with array indices "
                "in brackets, e.g. inflows[0].breach.average_width_m)")
        tokens = tuple(name if name else int(index) for name, index in _TOKEN.findall(text))
        return cls(text, tokens)

    @property
    def pattern(self) -> str:
        """The path with its indices left out (``inflows[].breach.average_width_m``)."""
        out = ""
        for token in self.tokens:
            out = f"{out}[]" if isinstance(token, int) else join(out, token)
        return out

    def __str__(self) -> str:
        return self.text


def _table_keys() -> dict[str, tuple[str, ...]]:
    """The keys each scenario table accepts, by table pattern (from the scenario's classes)."""
    from floodsph.breach.params import BreachParams
    from floodsph.scenario.config import (
        TOP_KEYS,
        Gauges,
        Inflow,
        InitialWater,
        OutputConfig,
        ScenarioInfo,
        Sink,
        TerrainConfig,
        Wall,
    )
    from floodsph.scenario.numerics import SCENARIO_KEYS as NUMERICS_KEYS

    def names(cls):
        return tuple(f.name for f in fields(cls) if f.metadata.get("scenario", True))

    return {
        "": TOP_KEYS,
        "scenario": names(ScenarioInfo),
        "terrain": names(TerrainConfig),
        "initial_water[]": names(InitialWater),
        "walls[]": names(Wall),
        "inflows[]": names(Inflow),
        "inflows[].breach": names(BreachParams),
        "sinks[]": names(Sink),
        "gauges": names(Gauges),
        "numerics": NUMERICS_KEYS,
        "output": names(OutputConfig),
    }


def lookup(data: dict, key: KeyPath):
    """The value at ``key`` in the resolved scenario ``data``, or :data:`MISSING`.

    Raises
    ------
    KeyPathError
        When a table or array entry on the way is absent from the base scenario, the last
        key is not one the scenario accepts there, or the path names a table.
    """
    tables = _table_keys()
    node, where, pattern = data, "", ""
    last = len(key.tokens) - 1
    for k, token in enumerate(key.tokens):
        if isinstance(node, dict):
            if isinstance(token, int):
                raise KeyPathError(f"{where or 'the scenario'} is a table, not an array")
            allowed = tables.get(pattern, ())
            if token not in allowed:
                raise KeyPathError(f"the scenario has no key {join(where, token)} (allowed in "
                                   f"{where or 'the top level'}: {', '.join(sorted(allowed))})")
            if token not in node:
                if k == last:
                    return MISSING
                raise KeyPathError(f"the base scenario has no {join(where, token)}")
            node, where, pattern = node[token], join(where, token), join(pattern, token)
        elif isinstance(node, list):
            if not isinstance(token, int):
                raise KeyPathError(f"{where} is an array: index it, e.g. {where}[0]")
            if token >= len(node):
                raise KeyPathError(f"the base scenario has no {where}[{token}] ({where} has "
                                   f"{len(node)} entr{'y' if len(node) == 1 else 'ies'})")
            node, where, pattern = node[token], join(where, token), f"{pattern}[]"
        else:
            raise KeyPathError(f"{where} is a value ({node!r}); it has no {token!r}")
    if isinstance(node, dict) or (isinstance(node, list) and node
                                  and all(isinstance(v, dict) for v in node)):
        raise KeyPathError(f"{key} is a table, not a value")
    return node


def base_value(data: dict, key: KeyPath):
    """The value a factor multiplies: :func:`lookup`, or a breach key's implied default.

    Returns :data:`MISSING` when the base scenario has no value there and none is implied.
    """
    value = lookup(data, key)
    if value is not MISSING or key.pattern.rsplit(".", 1)[0] != "inflows[].breach":
        return value
    from floodsph.breach.params import BreachParams, resolve

    index, name = key.tokens[1], key.tokens[-1]
    table = data["inflows"][index]["breach"]
    params = BreachParams.from_mapping(table, f"inflows[{index}].breach")
    if name in ("average_width_m", "formation_time_s"):
        return float(getattr(resolve(params), name))
    default = getattr(params, str(name))
    return MISSING if default is None else default


def assign(data: dict, key: KeyPath, value) -> dict:
    """A deep copy of ``data`` with ``value`` at ``key`` (the path must :func:`lookup`)."""
    out = copy.deepcopy(data)
    node = out
    for token in key.tokens[:-1]:
        node = node[token]
    node[key.tokens[-1]] = value
    return out
