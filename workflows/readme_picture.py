"""The README's picture: the UK hazard map of the sample scenario.

Runs ``data_samples/valley/scenario.toml`` (the synthetic valley's dam failure, 600 s) into a
temporary run folder with ``floodsph.run.pipeline.run_scenario`` and keeps the run's own quick-look
``hazard_uk.png`` as ``docs/images/sample_hazard.png``. Needs matplotlib
(``pip install -e ".[plot]"``).

Usage: ``python workflows/readme_picture.py [--out FILE] [--threads N]``
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SAMPLE = REPO / "data_samples" / "valley" / "scenario.toml"
PICTURE = REPO / "docs" / "images" / "sample_hazard.png"


def main(argv: list[str] | None = None) -> Path:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=PICTURE, help=f"default {PICTURE}")
    parser.add_argument("--threads", type=int, default=None, help="numba threads")
    args = parser.parse_args(argv)

    from floodsph.run.pipeline import run_scenario
    from floodsph.scenario.reader import load_scenario

    with tempfile.TemporaryDirectory() as tmp:
        run = Path(tmp) / "run"
        manifest = run_scenario(load_scenario(SAMPLE), run, progress=False,
                                threads=args.threads)
        made = run / "hazard_uk.png"
        if not made.is_file():
            raise SystemExit(f"the run wrote no {made.name} (is matplotlib installed?); "
                             f"status {manifest.get('status')}")
        args.out.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(made, args.out)
    print(f"wrote {args.out}")
    return args.out


if __name__ == "__main__":
    main()
