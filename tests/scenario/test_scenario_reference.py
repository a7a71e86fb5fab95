"""``docs/scenario-reference.md`` lists every key the scenario parser accepts, with the
defaults a run really uses, and is what ``workflows/scenario_reference.py`` writes now.

The keys the parser accepts are found by asking the parser itself: each table is given an
unknown key, and the refusal lists the allowed ones. So a key added to
``floodsph/scenario/config.py``
without its entry in ``floodsph/scenario/keys.py`` (and a re-generated page) fails here."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest
from conftest import load_script

from floodsph.errors import InputError
from floodsph.scenario.keys import TABLES
from floodsph.scenario.reader import scenario_from_dict

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "scenario-reference.md"
generator = load_script("scenario_reference", ROOT / "workflows" / "scenario_reference.py")
UNKNOWN = "zz_no_such_key"
REGENERATE = "re-run `python workflows/scenario_reference.py` and commit docs/scenario-reference.md"


def minimal(folder: Path) -> dict:
    """The smallest scenario the parser accepts (the DEM only has to exist at load time)."""
    dem = folder / "dem.tif"
    dem.write_bytes(b"")
    return {"scenario": {"name": "probe", "end_time_s": 1.0}, "terrain": {"dem": str(dem)}}


def refusal(data: dict, folder: Path) -> str:
    with pytest.raises(InputError) as caught:
        scenario_from_dict(data, source="probe.toml", base_dir=folder)
    return str(caught.value)


def allowed_keys(message: str) -> set[str]:
    """The key list of an unknown-key refusal (the scenario's or the breach table's form)."""
    found = re.search(r"(?:allowed keys: |expected one of: )([\w, ]+)", message)
    assert found, f"not an unknown-key refusal: {message}"
    return {k.strip() for k in found.group(1).split(",")}


def accepted(folder: Path) -> dict[str, set[str]]:
    """Table name -> the keys the parser accepts in it, found by probing the parser."""
    base = minimal(folder)
    tables = allowed_keys(refusal({**base, UNKNOWN: 1}, folder))
    out = {}
    for name in tables:
        data = {**base, name: {**base.get(name, {}), UNKNOWN: 1}}
        message = refusal(data, folder)
        if "expected an array of tables" in message:
            message = refusal({**base, name: [{UNKNOWN: 1}]}, folder)
        out[name] = allowed_keys(message)
    hydrograph = folder / "q.csv"
    hydrograph.write_text("time_s,discharge_m3s\n0,1\n10,1\n", encoding="utf-8")
    inflow = {"line": [[0.0, 0.0], [0.0, 10.0]], "breach": {UNKNOWN: 1}}
    out["inflows.breach"] = allowed_keys(refusal({**base, "inflows": [inflow]}, folder))
    wall = {"polyline": [[0.0, 0.0], [0.0, 10.0]], "crest_m": 1.0, "breach": {UNKNOWN: 1}}
    out["walls.breach"] = allowed_keys(refusal({**base, "walls": [wall]}, folder))
    return out


def page_keys(text: str) -> dict[str, dict[str, str]]:
    """Table name -> {key: default cell} as the page lists them."""
    out: dict[str, dict[str, str]] = {}
    table = None
    for line in text.splitlines():
        header = re.match(r"## `\[\[?([\w.]+)\]?\]`", line)
        if header:
            table = out.setdefault(header.group(1), {})
        row = re.match(r"\| `(\w+)` \|(?:[^|]|\\\|)*?\| [^|]* \| (.*?) \| ", line)
        if row and table is not None:
            table[row.group(1)] = row.group(2)
    return out


@pytest.fixture(scope="module")
def parser_keys(tmp_path_factory):
    return accepted(tmp_path_factory.mktemp("probe"))


def test_every_key_the_parser_accepts_is_on_the_page(parser_keys):
    listed = page_keys(PAGE.read_text(encoding="utf-8"))
    missing = sorted(f"{t}.{k}" for t, keys in parser_keys.items() for k in keys
                     if k not in listed.get(t, {}))
    assert not missing, (f"accepted by the parser but not in docs/scenario-reference.md: "
                         f"{missing}; add a KeyDoc to floodsph/scenario/keys.py and {REGENERATE}")


def test_every_key_on_the_page_is_accepted_by_the_parser(parser_keys):
    documented = {t.name: {k.name for k in t.keys} for t in TABLES}
    extra = sorted(f"{t}.{k}" for t, keys in documented.items() for k in keys
                   if k not in parser_keys.get(t, set()))
    assert not extra, f"documented in floodsph/scenario/keys.py but refused by the parser: {extra}"


def test_the_page_shows_the_defaults_a_loaded_scenario_gets(tmp_path):
    """Defaults written as values (`0.3`, `"open"`) are those of a scenario loaded without
    the key: the page cannot promise one value while the parser fills in another."""
    gauges = tmp_path / "gauges.csv"
    gauges.write_text("id,x,y\n", encoding="utf-8")
    data = {**minimal(tmp_path), "gauges": {"file": str(gauges)}}
    resolved = scenario_from_dict(data, source="probe.toml", base_dir=tmp_path).to_dict()
    listed = page_keys(PAGE.read_text(encoding="utf-8"))
    compared = 0
    for table in ("scenario", "terrain", "gauges", "numerics", "output"):
        for key, cell in listed[table].items():
            value = re.fullmatch(r"`(.*)`", cell)
            if value is None:
                continue
            shown = tomllib.loads(f"v = {value.group(1)}")["v"]
            assert resolved[table][key] == shown, f"{table}.{key}: page {shown!r}"
            compared += 1
    assert compared >= 15


def test_the_committed_page_is_what_the_generator_writes_now(tmp_path):
    fresh = generator.main(["--out", str(tmp_path / "page.md")]).read_text(encoding="utf-8")
    assert PAGE.read_text(encoding="utf-8") == fresh, f"docs/scenario-reference.md is stale: "\
                                                       f"{REGENERATE}"
