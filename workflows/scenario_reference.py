"""Write ``docs/scenario-reference.md``: every table and key of the scenario file.

The page is made from ``floodsph.scenario.keys.TABLES`` (type, units and meaning of each key)
and the defaults of the dataclasses the parser fills, so it shows what the code accepts.
Re-run it after adding or changing a key; ``tests/scenario/test_scenario_reference.py`` fails while
the committed page differs from what this script writes.

Usage: ``python workflows/scenario_reference.py [--out FILE]``
"""

from __future__ import annotations

import argparse
from pathlib import Path

DOC = Path(__file__).resolve().parents[1] / "docs" / "scenario-reference.md"

INTRO = """\
# Scenario file reference

One TOML file describes one scenario. Units are SI; coordinates are in the DEM's CRS
(projected, metres); relative paths are relative to the scenario file. An unknown key, a
wrong type or an impossible value is refused before anything runs, with one message naming
the file and the key path (`inflows[0].hydrograph`). `data_samples/valley/scenario.toml` is
a complete example; `floodsph check SCENARIO` validates a file and its inputs.

Tables written `[[name]]` may be repeated; a table that is not required may be left out.
A default in quotes is a string; `none` means the feature is off unless the key is given.

This page is generated from the code (`floodsph/scenario/keys.py` and the parser's
defaults) by `python workflows/scenario_reference.py`; do not edit it by hand.
"""


def cell(text: str) -> str:
    """``text`` safe inside a markdown table cell."""
    return text.replace("|", "\\|").replace("\n", " ")


def table_section(table) -> list[str]:
    """The markdown of one table: its header, what it is for, and a row per key."""
    need = "Required" if table.required else ("Optional, repeatable" if table.array
                                              else "Optional")
    lines = [f"## `{table.header}`", "", f"{table.meaning} {need}.", "",
             "| key | type | units | default | meaning |", "| --- | --- | --- | --- | --- |"]
    for key in table.keys:
        default = table.default_text(key)
        shown = f"`{default}`" if default[:1] in '"[-0123456789' or default in (
            "true", "false") else default
        lines.append(f"| `{key.name}` | {cell(table.type_text(key))} | {key.units or '-'} | "
                     f"{cell(shown)} | {cell(key.meaning)} |")
    return lines + [""]


def render() -> str:
    """The whole page."""
    from floodsph.scenario.keys import TABLES

    lines = [INTRO]
    for table in TABLES:
        lines.extend(table_section(table))
    return "\n".join(lines).rstrip() + "\n"


def main(argv: list[str] | None = None) -> Path:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=DOC, help=f"the page (default {DOC})")
    args = parser.parse_args(argv)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(render(), encoding="utf-8")
    print(f"wrote {args.out}")
    return args.out


if __name__ == "__main__":
    main()
