"""The ``hexdem`` command line: one small module per subcommand (see :mod:`.main`)."""
