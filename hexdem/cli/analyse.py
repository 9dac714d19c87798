"""``hexdem analyse``: result files from the dump of a deck run by hand (through MDAnalysis).

MDAnalysis is an optional dependency, the extra ``dumps``: without it the command says in one line
what to install.
"""

from __future__ import annotations

from hexdem.errors import HexdemError

INSTALL_DUMPS = 'pip install "hexdem[dumps]"'


def add_arguments(parser) -> None:
    parser.add_argument(
        "deck",
        metavar="DECKDIR",
        help="a deck directory written by hexdem run (DIR/deck), "
        "whose dump.lammpstrj was written by lmp -in in.hexdem or hexdem run --dump",
    )
    parser.add_argument("--out", metavar="DIR", help="output directory (default: the deck's parent directory)")


def run(args) -> None:
    try:
        import MDAnalysis  # noqa: F401
    except ImportError:
        raise HexdemError(
            f"hexdem analyse reads dumps through MDAnalysis, which is not installed; install it with: {INSTALL_DUMPS}"
        ) from None
    from hexdem.experiments.analyse import analyse_deck

    analyse_deck(args.deck, args.out)
