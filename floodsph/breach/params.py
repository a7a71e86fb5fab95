"""Breach parameters: the validated ``[breach]`` / ``[inflows.breach]`` table and its derived setup.

See :mod:`floodsph.breach` for the table of keys. Every error names the key path (and the file
when there is one), e.g. ``inflows[0].breach.reservoir_volume_m3: must be > 0``.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path

from floodsph.breach import formulas
from floodsph.breach.storage import Storage, read_storage_table
from floodsph.constants import LARGEST_VALUE
from floodsph.errors import InputError
from floodsph.io.hydrograph import Hydrograph, read_hydrograph

#: Relative tolerance on reservoir_volume_m3 against the volume implied by the storage input.
VOLUME_TOLERANCE = 0.01

_CHOICES = {"method": ("froehlich2008",), "mode": ("overtopping", "piping"),
            "progression": ("linear", "sine")}
_POSITIVE = ("breach_height_m", "reservoir_volume_m3", "head_m", "reservoir_area_m2",
             "weir_coefficient", "average_width_m", "formation_time_s", "duration_s", "dt_s")
_PATHS = ("storage_table", "inflow_hydrograph")


@dataclass(frozen=True)
class BreachParams:
    """User breach parameters, checked for type and range (see :mod:`floodsph.breach`)."""

    breach_height_m: float
    method: str = "froehlich2008"
    mode: str = "overtopping"
    reservoir_volume_m3: float | None = None
    head_m: float | None = None
    initial_level_m: float | None = None
    breach_invert_m: float = 0.0
    reservoir_area_m2: float | None = None
    storage_table: Path | None = None
    inflow_hydrograph: Path | None = None
    progression: str = "linear"
    weir_coefficient: float = formulas.WEIR_COEFFICIENT
    average_width_m: float | None = None
    formation_time_s: float | None = None
    start_time_s: float = 0.0
    duration_s: float | None = None
    dt_s: float | None = None
    key: str = field(default="breach", compare=False, metadata={"scenario": False})
    """The key path of the table (with its file), prefix of error messages; no key itself."""

    @classmethod
    def from_mapping(cls, table, key="breach", base_dir=".", source=None):
        """Validate a parsed TOML table.

        Parameters
        ----------
        table : Mapping
            The key/value pairs of the breach table.
        key : str
            Its key path, e.g. ``inflows[0].breach`` (prefix of every error message).
        base_dir : str or os.PathLike
            Folder that relative paths (storage_table, inflow_hydrograph) are relative to.
        source : str or os.PathLike, optional
            The file the table came from, named at the start of error messages.
        """
        prefix = f"{source}: {key}" if source else key
        known = {f.name for f in fields(cls)} - {"key"}
        values = {}
        for name, value in table.items():
            where = f"{prefix}.{name}"
            if name not in known:
                raise InputError(
                    f"{where}: unknown key (expected one of: {', '.join(sorted(known))})")
            if name in _CHOICES:
                if value not in _CHOICES[name]:
                    raise InputError(f"{where}: {value!r} is not one of "
                                     f"{', '.join(map(repr, _CHOICES[name]))}")
            elif name in _PATHS:
                if not isinstance(value, str) or not value:
                    raise InputError(f"{where}: expected a file path string, got {value!r}")
                value = Path(base_dir) / value
            else:
                if isinstance(value, bool) or not isinstance(value, int | float):
                    raise InputError(f"{where}: expected a number, got {value!r}")
                value = float(value)
                if not math.isfinite(value):
                    raise InputError(f"{where}: must be finite, got {value}")
                if abs(value) > LARGEST_VALUE:
                    raise InputError(f"{where}: {value:g} is beyond +-{LARGEST_VALUE:g}, more "
                                     "than any quantity of a flood scenario in SI units")
                if name in _POSITIVE and value <= 0.0:
                    raise InputError(f"{where}: must be > 0, got {value:g}")
            values[name] = value
        if "breach_height_m" not in values:
            raise InputError(f"{prefix}.breach_height_m: required key missing")
        for first, second in (("head_m", "initial_level_m"),
                              ("reservoir_area_m2", "storage_table")):
            if first in values and second in values:
                raise InputError(f"{prefix}: give {first} or {second}, not both")
        if not {"reservoir_volume_m3", "reservoir_area_m2", "storage_table"} & values.keys():
            raise InputError(f"{prefix}.reservoir_volume_m3: required key missing (or give "
                             "reservoir_area_m2 or storage_table)")
        return cls(key=prefix, **values)


def load_breach_params(path, overrides=None):
    """Read a standalone breach file: a TOML document with one ``[breach]`` table.

    Relative paths in it are relative to the file's folder. ``overrides`` (a mapping of the
    same keys, e.g. from command-line options) replace the file's values before validation.
    """
    path = Path(path)
    try:
        with open(path, "rb") as stream:
            document = tomllib.load(stream)
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except (OSError, tomllib.TOMLDecodeError) as err:
        raise InputError(f"{path}: not a valid TOML file ({err})") from None
    extra = sorted(set(document) - {"breach"})
    if extra:
        raise InputError(f"{path}: unknown table or key {extra[0]!r} (expected only [breach])")
    if not isinstance(document.get("breach"), dict):
        raise InputError(f"{path}: missing [breach] table")
    table = {**document["breach"], **(overrides or {})}
    return BreachParams.from_mapping(table, "breach", path.parent, source=path)


@dataclass(frozen=True, eq=False)
class BreachSetup:
    """Everything the routing needs, derived from :class:`BreachParams`.

    Attributes: storage curve; reservoir inflow (or None); ``volume_m3`` V_w and ``head_m``
    h_w used by the regressions; ``initial_level_m`` H0; ``top_m`` the breach bottom at
    initiation (the lower of the dam crest at the breach, invert + h_b, and H0);
    ``invert_m``; ``average_width_m`` B_avg; ``bottom_width_m``; ``side_slope`` z (H:V);
    ``formation_time_s`` t_f.
    """

    params: BreachParams
    storage: Storage
    inflow: Hydrograph | None
    volume_m3: float
    head_m: float
    initial_level_m: float
    top_m: float
    invert_m: float
    average_width_m: float
    bottom_width_m: float
    side_slope: float
    formation_time_s: float


def _storage(p):
    """Storage curve and the stored volume above the invert at the initial level."""
    h_b, invert = p.breach_height_m, p.breach_invert_m
    level = (p.initial_level_m if p.initial_level_m is not None
             else invert + (p.head_m if p.head_m is not None else h_b))
    head = level - invert
    if head <= 0.0:
        raise InputError(f"{p.key}.initial_level_m: {level:g} must be above breach_invert_m "
                         f"({invert:g})")
    if p.storage_table is not None:
        name = f"{p.key}.storage_table"
        storage = read_storage_table(p.storage_table, name)
        if storage.z[0] > invert:
            raise InputError(f"{name}: {p.storage_table}: the lowest elevation {storage.z[0]:g} "
                             f"is above breach_invert_m ({invert:g})")
        if level > storage.z[-1]:
            raise InputError(f"{name}: {p.storage_table}: the highest elevation "
                             f"{storage.z[-1]:g} is below the initial level ({level:g})")
    elif p.reservoir_area_m2 is not None:
        storage = Storage.constant_area(p.reservoir_area_m2, invert)
    else:
        storage = Storage.constant_area(p.reservoir_volume_m3 / head, invert)
    stored = storage.volume(level) - storage.volume(invert)
    given = p.storage_table is not None or p.reservoir_area_m2 is not None
    if (given and p.reservoir_volume_m3 is not None
            and abs(p.reservoir_volume_m3 - stored) > VOLUME_TOLERANCE * stored):
        source = "storage_table" if p.storage_table is not None else "reservoir_area_m2"
        raise InputError(
            f"{p.key}.reservoir_volume_m3: {p.reservoir_volume_m3:g} m3 disagrees with the "
            f"{stored:g} m3 that {source} holds above breach_invert_m at the initial level "
            "(give only one of them, or make them agree within 1 %)")
    return storage, level, head, stored


def resolve(params: BreachParams) -> BreachSetup:
    """Derive storage, Froehlich (2008) breach size and formation time from the parameters."""
    p = params
    storage, level, head, stored = _storage(p)
    volume = p.reservoir_volume_m3 if p.reservoir_volume_m3 is not None else stored
    h_b = p.breach_height_m
    average = (p.average_width_m if p.average_width_m is not None
               else formulas.froehlich2008_average_width(volume, h_b, p.mode))
    t_f = (p.formation_time_s if p.formation_time_s is not None
           else formulas.froehlich2008_formation_time(volume, h_b))
    side = formulas.FROEHLICH2008_SIDE_SLOPE[p.mode]
    if p.dt_s is not None and p.dt_s > t_f / 10.0:
        raise InputError(f"{p.key}.dt_s: {p.dt_s:g} s is too coarse for the breach formation "
                         f"time {t_f:g} s (must be <= t_f / 10)")
    inflow = (read_hydrograph(p.inflow_hydrograph, f"{p.key}.inflow_hydrograph")
              if p.inflow_hydrograph is not None else None)
    invert = p.breach_invert_m
    return BreachSetup(
        params=p, storage=storage, inflow=inflow, volume_m3=volume, head_m=head,
        initial_level_m=level, top_m=min(invert + h_b, level), invert_m=invert,
        average_width_m=average, bottom_width_m=formulas.bottom_width(average, side, h_b),
        side_slope=side, formation_time_s=t_f)
