"""The paper's cases n = 1, 2, 3: stability maps with the closed-form boundaries, checked.

    python scripts/paper_cases.py --check                    # every case; figures in paper-cases/ (about 1 minute)
    python scripts/paper_cases.py --check --quick            # coarse grids, 3 rows per case (the test suite runs this)
    python scripts/paper_cases.py --golden tests/data        # rewrite the golden atlases the tests pin
    python scripts/paper_cases.py --case paper-n1-fixed-dry --out figs

What each case computes and checks: the docstring of ``stabmap.paper.gyroscopes``.

``--check`` exits 1 if anything disagrees, and prints which case, row and value.

The checks themselves live in ``stabmap.paper.gyroscopes`` and run as ``stabmap paper gyroscopes``
from an installed stabmap; this script keeps the old options and ``--golden``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from stabmap.paper.gyroscopes import *  # noqa: F401,F403  (tests/test_paper_cases.py reads these names)
from stabmap.paper.gyroscopes import CASES, RTOL, check_case, run, write_golden  # noqa: F401


def main(argv: list[str] | None = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="exit 1 if any boundary or label disagrees with the paper")
    p.add_argument("--quick", action="store_true", help="coarse grids (60 x 40) and 3 rows per case")
    p.add_argument("--case", action="append", choices=[c.name for c in CASES], help="only this case (repeatable)")
    p.add_argument("--rows", type=int, help="rows of the second axis checked per case (default 15, quick 3)")
    p.add_argument("--out", type=Path, default=Path("paper-cases"), help="directory for the figures (default paper-cases/)")
    p.add_argument("--no-figures", action="store_true", help="check only")
    p.add_argument("--golden", type=Path, metavar="DIR", help="write the golden atlases to DIR and stop")
    args = p.parse_args(argv)
    if args.golden:
        for path in write_golden(args.golden):
            print(f"wrote {path}")
        return {}
    if args.rows is not None and args.rows < 1:
        p.error("--rows must be >= 1")
    out = None if args.no_figures else args.out
    done = run(args.case, quick=args.quick, rows=args.rows, out=out)
    print(f"# command: python scripts/paper_cases.py {' '.join(argv if argv is not None else sys.argv[1:])}")
    print(done["text"])
    if out is not None:
        print(f"\nfigures in {out}/")
    if args.check and done["problems"]:
        sys.exit(1)
    return done


if __name__ == "__main__":
    main()
