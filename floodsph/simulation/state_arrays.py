"""The state of a run as named arrays: declared by each class, flattened to dotted names.

Every class whose objects change while a run goes (the model, its particles and lists, each
open boundary, the refiner, the flux lines) declares its state as a class-level tuple
``STATE`` of attribute names; everything else about the object is made again from the
scenario when a run resumes. :func:`capture` reads the declared attributes, :func:`restore`
writes them back into an object built afresh, checking each value against the fresh one
(:func:`conform`). A checkpoint (``floodsph.simulation.checkpoint``) stores the tree of
captured states as flat arrays named by their path (:func:`flatten`), ``model.particles.x``
or ``model.boundaries.0.buffer.x``, and reads them back with :func:`unflatten`.

The values of a state, and how they are stored:

* numpy arrays (bool, integer or float, at least 1-d): as they are;
* numbers (bool, int, float, numpy scalars): 0-d arrays, read back as Python numbers;
* dicts with str keys: one name per entry, ``name.key`` (an empty dict as JSON ``{}``);
* anything else that JSON writes (str, None, lists and tuples of numbers and strings, such
  as the rows of a table): JSON text in a 0-d unicode array, read back by ``json.loads``
  (tuples come back as lists; floats, infinities and NaN exactly).

Nothing stored is code, and nothing read runs any: the arrays are read with numpy's
``allow_pickle=False``, and JSON holds data only.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import numpy as np

from floodsph.errors import InputError

SEPARATOR = "."
"""Between the parts of a name: ``model.particles.x``."""
ARRAY_KINDS = "biuf"
"""numpy dtype kinds stored as arrays: bool, signed and unsigned integers, floats."""


def capture(obj) -> dict[str, Any]:
    """The declared state of ``obj``: ``{name: getattr(obj, name)}`` for each name of its
    class's ``STATE`` (module docstring)."""
    names = getattr(type(obj), "STATE", None)
    if names is None:
        raise TypeError(f"{type(obj).__name__} declares no STATE: list the attributes that "
                        "change during a run (floodsph.simulation.state_arrays)")
    return {name: getattr(obj, name) for name in names}


def restore(obj, state: Mapping[str, Any], where: str, source: str) -> None:
    """Set the declared state of ``obj`` (built afresh) from ``state``, in the order of its
    ``STATE``; each value is checked against the fresh one (:func:`conform`).

    ``where`` is the state's name (``model.boundaries.0``), ``source`` the file it was read
    from, both for the message of the :class:`InputError` raised for a missing, extra or
    ill-formed field.
    """
    names = type(obj).STATE
    expect_fields(state, names, where, source)
    for name in names:
        field = joined(where, name)
        value = conform(getattr(obj, name), state[name], field, source)
        try:
            setattr(obj, name, value)
        except (ValueError, TypeError) as exc:
            raise InputError(f"{source}: the field {field} does not fit ({exc})") from None


def expect_fields(state, names, where: str, source: str) -> None:
    """Refuse ``state`` unless it is a mapping with exactly the fields ``names``."""
    if not isinstance(state, Mapping):
        raise InputError(f"{source}: the field {where} is not a group of fields")
    missing = [name for name in names if name not in state]
    if missing:
        raise InputError(f"{source}: the field {joined(where, missing[0])} is missing")
    extra = sorted(set(state) - set(names))
    if extra:
        raise InputError(f"{source}: the field {joined(where, extra[0])} is not one this "
                         "floodsph knows")


def joined(where: str, name: str) -> str:
    """The dotted name of the field ``name`` of the group ``where`` (top level: ``""``)."""
    return f"{where}{SEPARATOR}{name}" if where else name


def conform(template, value, where: str, source: str):
    """``value`` read back for a field whose fresh value is ``template``, checked: a dict
    with the same keys (in the template's order, each conformed), an array of the same
    kind of dtype and number of dimensions, a number for a number, a list for a list, a str
    for a str. A template of None (a field not yet set) takes any value."""
    if template is None:
        return value
    if isinstance(template, Mapping):
        expect_fields(value, tuple(template), where, source)
        return {key: conform(template[key], value[key], joined(where, key), source)
                for key in template}
    if isinstance(template, np.ndarray) and template.ndim > 0:
        if (not isinstance(value, np.ndarray) or value.ndim != template.ndim
                or value.dtype.kind != template.dtype.kind):
            raise InputError(f"{source}: the field {where} is not a {template.ndim}-d array "
                             f"of {template.dtype}")
        return np.require(value, template.dtype, ["C_CONTIGUOUS", "WRITEABLE"])
    if _is_number(template):
        if not _is_number(value):
            raise InputError(f"{source}: the field {where} is not a number")
        return value
    if isinstance(template, list | tuple) and not isinstance(value, list):
        raise InputError(f"{source}: the field {where} is not a list")
    if isinstance(template, str) and not isinstance(value, str):
        raise InputError(f"{source}: the field {where} is not a text")
    return value


def _is_number(value) -> bool:
    return isinstance(value, bool | int | float | np.number | np.bool_) or (
        isinstance(value, np.ndarray) and value.ndim == 0)


def flatten(tree: Mapping[str, Any], prefix: str = "") -> dict[str, np.ndarray]:
    """The arrays of ``tree`` (nested dicts of state values) by dotted name (module
    docstring)."""
    out: dict[str, np.ndarray] = {}
    for key, value in tree.items():
        if not isinstance(key, str) or not key or SEPARATOR in key:
            raise ValueError(f"state name {prefix}{key!r}: a non-empty str without "
                             f"{SEPARATOR!r} is needed")
        name = prefix + key
        if isinstance(value, Mapping) and value:
            out.update(flatten(value, name + SEPARATOR))
        else:
            out[name] = _leaf(value, name)
    return out


def _leaf(value, name: str) -> np.ndarray:
    """One stored value: an array as it is, a number as a 0-d array, else JSON text."""
    if isinstance(value, np.ndarray) and value.ndim > 0:
        if value.dtype.kind not in ARRAY_KINDS:
            raise TypeError(f"state {name}: arrays of {value.dtype} are not stored")
        return value
    if _is_number(value):
        return np.asarray(value)
    return np.asarray(json.dumps(value, default=_plain, allow_nan=True))


def _plain(value):
    """JSON for numpy scalars inside lists (a gauge's depth, say)."""
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not stored in a checkpoint")


def unflatten(arrays: Mapping[str, np.ndarray], source: str) -> dict[str, Any]:
    """The tree of state values from arrays named by :func:`flatten` (read from ``source``,
    for messages)."""
    tree: dict[str, Any] = {}
    for name, array in arrays.items():
        parts = name.split(SEPARATOR)
        node = tree
        for depth, part in enumerate(parts[:-1]):
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise InputError(f"{source}: the field {SEPARATOR.join(parts[:depth + 1])} "
                                 "is both a value and a group of fields")
        if parts[-1] in node:
            raise InputError(f"{source}: the field {name} is both a value and a group of "
                             "fields")
        node[parts[-1]] = _value(array, name, source)
    return tree


def _value(array: np.ndarray, name: str, source: str):
    """The state value of one stored array (the inverse of :func:`_leaf`)."""
    if array.dtype.kind == "U" and array.ndim == 0:
        try:
            return json.loads(str(array))
        except ValueError:
            raise InputError(f"{source}: the field {name} is not readable JSON") from None
    if array.dtype.kind not in ARRAY_KINDS:
        raise InputError(f"{source}: the field {name} holds {array.dtype}, not numbers")
    if array.ndim == 0:
        return array.item()
    return array
