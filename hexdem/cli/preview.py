"""``hexdem preview``: draw a packing (beads, walls, impacts, observation lines) without running it."""

from __future__ import annotations

import sys

from hexdem.model.config import RunConfig


def add_arguments(parser) -> None:
    parser.add_argument(
        "--config",
        metavar="FILE.toml",
        help="parameters, as for hexdem run (default: the paper's 11-per-edge steel experiment)",
    )
    parser.add_argument(
        "--out", metavar="DIR", default="results", help="output directory of DIR/preview.png (default: results/)"
    )


def run(args) -> None:
    from hexdem.experiments.preview import preview

    path = preview(RunConfig.from_toml(args.config) if args.config else RunConfig(), args.out)
    print(f"hexdem: preview in {path}", file=sys.stderr)
