"""``python -m hexdem``: the ``hexdem`` command."""

import sys

from hexdem.cli.main import command

sys.exit(command())
