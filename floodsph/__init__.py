"""floodsph: dam-breach flood mapping on real terrain with shallow-water SPH.

The public calls (``docs/api.md``)::

    import floodsph

    scenario = floodsph.load_scenario("scenario.toml")
    result = floodsph.run_scenario(scenario)
    result.folder, result.manifest, result.maps()   # run folder, run.json, xarray.Dataset

They are imported on first use (module ``__getattr__``), so that ``import floodsph`` and the
command line's ``--help`` load no numba, rasterio or xarray.
"""

from importlib import import_module as _import_module

from floodsph._version import __version__

#: Public name -> the module that defines it.
_PUBLIC = {
    "load_scenario": "floodsph.scenario.reader",
    "Scenario": "floodsph.scenario.config",
    "run_scenario": "floodsph.api",
    "RunResult": "floodsph.run.results",
    "open_run": "floodsph.run.results",
    "InputError": "floodsph.errors",
}

__all__ = ["__version__", *_PUBLIC]


def __getattr__(name: str):
    if name not in _PUBLIC:
        raise AttributeError(f"module 'floodsph' has no attribute {name!r}")
    value = getattr(_import_module(_PUBLIC[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_PUBLIC})
