"""References a reader can follow: every document, section, file and module the package and
its documentation cite exists in the repository.

Checked in ``floodsph/**/*.py`` and ``docs/**/*.md``:

* no citation of documents that are not in the repository (``architecture.md``,
  ``scenario-format.md``, ``sph-swe-method.md``, ``flood-practice.md``, ``peers.md``, "method
  notes");
* every ``docs/NAME.md`` exists, and so does every relative Markdown link between the docs;
* every ``docs/method.md §N`` (or ``§N.M``) is a numbered heading of ``docs/method.md``;
* every ``floodsph/....py``, ``workflows/....py`` and ``benchmarks/....py`` path exists (a
  script moved between the user's ``workflows/`` and the studies' ``benchmarks/`` is cited
  where it now is), and every dotted ``floodsph.package.module[.name]`` names a module and,
  after it, a name that module defines at its top level.
"""

from __future__ import annotations

import ast
import re
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
METHOD = ROOT / "docs" / "method.md"
ABSENT = ("architecture.md", "scenario-format.md", "sph-swe-method.md", "flood-practice.md",
          "peers.md", "method notes", "shared/reference")


def _files() -> list[Path]:
    return sorted([*(ROOT / "floodsph").rglob("*.py"), *(ROOT / "docs").rglob("*.md")])


def _where(path: Path, text: str, pos: int) -> str:
    return f"{path.relative_to(ROOT)}:{text.count(chr(10), 0, pos) + 1}"


def method_sections(text: str | None = None) -> set[str]:
    """The numbers of the headings of docs/method.md: '3', '3.1', ..."""
    text = METHOD.read_text(encoding="utf-8") if text is None else text
    return set(re.findall(r"^#{2,4}\s+(\d+(?:\.\d+)*)\.?\s", text, flags=re.M))


SECTION_REF = re.compile(r"method\.md`{0,2},?((?:\s*(?:§\s*\d+(?:\.\d+)*)\s*(?:,|and|-)?)+)")


def cited_sections(text: str, own: bool = False) -> list[tuple[int, str]]:
    """(position, number) of every § of docs/method.md cited in ``text``; with ``own`` (the
    text is docs/method.md itself) a bare § counts too."""
    found = []
    for m in SECTION_REF.finditer(text):
        found += [(m.start(), n) for n in re.findall(r"§\s*(\d+(?:\.\d+)*)", m.group(1))]
    if own:
        found += [(m.start(), m.group(1)) for m in re.finditer(r"§\s*(\d+(?:\.\d+)*)", text)]
    return found


@cache
def _top_level_names(path: Path) -> frozenset[str]:
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split(".")[0] for a in node.names)
        elif isinstance(node, (ast.Name,)) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.arg):
            continue
    return frozenset(names)


def _module_file(parts: list[str]) -> Path | None:
    rel = ROOT.joinpath(*parts)
    for candidate in (rel.with_suffix(".py"), rel / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def dotted_problem(name: str) -> str | None:
    """Why ``floodsph.a.b...`` does not resolve, or None. Only names inside a subpackage are
    judged (``floodsph.run_scenario`` and ``floodsph.log`` are the package's API and a file)."""
    parts = name.split(".")
    if len(parts) < 3 or not (ROOT / "floodsph" / parts[1]).is_dir():
        return None
    for k in range(len(parts), 1, -1):
        module = _module_file(parts[:k])
        if module is not None:
            break
    else:
        return "no such module"
    rest = parts[k:]
    if rest and rest[0] not in _top_level_names(module):
        return f"{'.'.join(parts[:k])} defines no {rest[0]}"
    return None


def problems() -> list[str]:
    found = []
    sections = method_sections()
    for path in _files():
        text = path.read_text(encoding="utf-8")
        for word in ABSENT:
            for m in re.finditer(re.escape(word), text):
                found.append(f"{_where(path, text, m.start())}: cites {word}, not in the repo")
        for m in re.finditer(r"docs/([\w./-]+\.md)", text):
            if not (ROOT / "docs" / m.group(1)).is_file():
                found.append(f"{_where(path, text, m.start())}: no file docs/{m.group(1)}")
        if path.suffix == ".md":
            for m in re.finditer(r"\]\(([^)#:\s]+\.md)(?:#[^)]*)?\)", text):
                if not (path.parent / m.group(1)).is_file():
                    found.append(f"{_where(path, text, m.start())}: broken link {m.group(1)}")
        for pos, number in cited_sections(text, own=path == METHOD):
            if number not in sections:
                found.append(f"{_where(path, text, pos)}: docs/method.md has no §{number}")
        for m in re.finditer(r"(?<![\w/])(?:floodsph|workflows|benchmarks)/[\w/]+\.py", text):
            if not (ROOT / m.group(0)).is_file():
                found.append(f"{_where(path, text, m.start())}: no file {m.group(0)}")
        for m in re.finditer(r"floodsph(?:\.[A-Za-z_]\w*)+", text):
            why = dotted_problem(m.group(0).rstrip("."))
            if why:
                found.append(f"{_where(path, text, m.start())}: {m.group(0)}: {why}")
    return found


def test_method_sections_are_numbered():
    assert {"1", "2", "3", "3.1", "3.6", "5", "8"} <= method_sections()


def test_every_reference_resolves():
    found = problems()
    assert not found, "references that lead nowhere:\n" + "\n".join(found)


@pytest.mark.parametrize("text, bad", [
    ("see ``docs/method.md`` §3.6 and docs/method.md §§", set()),
    ("(``docs/method.md`` §99)", {"99"}),
    ("docs/method.md §2, §42", {"42"}),
])
def test_a_missing_section_is_found(text, bad):
    cited = {n for _, n in cited_sections(text)}
    assert cited - method_sections() == bad


def test_a_moved_module_is_found():
    assert dotted_problem("floodsph.sph.forces.internal_acceleration") is None
    assert dotted_problem("floodsph.walls.shadow.shadow") == "floodsph.walls defines no shadow"
    assert dotted_problem("floodsph.sph.forces.no_such_kernel") is not None
