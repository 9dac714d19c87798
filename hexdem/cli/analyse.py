"""``hexdem analyse``: result files from the dump of a deck run by hand (through MDAnalysis)."""

from __future__ import annotations


def add_arguments(parser) -> None:
    parser.add_argument("deck", metavar="DECKDIR", help="a deck directory written by hexdem run (DIR/deck), "
                        "whose dump.lammpstrj was written by lmp -in in.hexdem or hexdem run --dump")
    parser.add_argument("--out", metavar="DIR", help="output directory (default: the deck's parent directory)")


def run(args) -> None:
    from hexdem.experiments.analyse import analyse_deck

    analyse_deck(args.deck, args.out)
