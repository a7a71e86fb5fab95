"""README.md is a short user guide whose commands and links work: at most 200 lines, its
first two fenced blocks are the `sh` set-up commands (the second the test command of
``.ci/run``, which then runs the studies' checks apart with ``-m benchmark``), every relative
link points to a file of the repository, and every ``floodsph <command>`` it shows (as a
command line, in code) is a command of the CLI."""

from __future__ import annotations

import re
from pathlib import Path

import click

from floodsph.cli.main import cli

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")
MAX_LINES = 200


def fenced_blocks(text: str) -> list[tuple[str, str]]:
    """(language, body) of each fenced code block, in order."""
    return re.findall(r"^```(\w*)\n(.*?)^```", text, flags=re.M | re.S)


def test_the_readme_is_at_most_200_lines():
    assert len(README.splitlines()) <= MAX_LINES


def test_the_first_two_blocks_are_the_sh_set_up_commands():
    blocks = fenced_blocks(README)
    assert [lang for lang, _ in blocks[:2]] == ["sh", "sh"]
    install, tests = (body for _, body in blocks[:2])
    assert "pip install -e ." in install and "floodsph run data_samples/" in install
    sample = re.search(r"floodsph run (\S+)", install).group(1)
    assert (ROOT / sample).is_file(), f"the sample {sample} does not exist"
    assert 'pip install -e ".[test]"' in tests


def test_the_test_command_is_the_one_ci_runs():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    ci_tests = [line.strip() for line in ci.splitlines()
                if "pytest" in line and not line.lstrip().startswith("#")]
    assert ci_tests == ["python -m pytest -q", "python -m pytest -q -m benchmark"]
    assert '-e ".[test]"' in ci
    _, tests = fenced_blocks(README)[1]
    assert tests.strip().endswith("&& " + ci_tests[0])


def test_every_relative_link_points_to_a_file():
    links = re.findall(r"\]\(([^)\s]+)\)", README)
    relative = [link.split("#")[0] for link in links if not re.match(r"\w+://", link)]
    assert relative, "no relative links found"
    missing = [link for link in relative if link and not (ROOT / link).exists()]
    assert not missing, f"README.md links to missing files: {missing}"


def test_every_floodsph_command_shown_exists_in_the_cli():
    code = re.findall(r"`([^`\n]+)`", README) + [body for _, body in fenced_blocks(README)]
    commands = [part.strip() for text in code for line in text.splitlines()
                for part in line.split("&&")]
    shown = {m.group(1) for c in commands if (m := re.match(r"floodsph ([a-z][\w-]*)", c))}
    assert {"run", "check", "ensemble", "breach", "compare"} <= shown
    ctx = click.Context(cli)
    unknown = sorted(name for name in shown if cli.get_command(ctx, name) is None)
    assert not unknown, f"README.md shows commands the CLI does not have: {unknown}"
