"""Writing a scenario back as TOML: the run folder's resolved copy (``tomli-w``)."""

from __future__ import annotations

from pathlib import Path

from floodsph.scenario.config import Scenario


def write_resolved(scenario: Scenario, path: Path) -> None:
    """Write the resolved scenario (absolute paths, defaults filled) as TOML to ``path``."""
    from tomli_w import dumps

    header = (
        f"# Resolved copy of {scenario.path}\n"
        "# (absolute paths and every default filled in; loads back into the same scenario)\n\n"
    )
    Path(path).write_text(header + dumps(scenario.to_dict()), encoding="utf-8")
