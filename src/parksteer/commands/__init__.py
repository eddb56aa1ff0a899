"""Subcommands of the ``parksteer`` command line, one module per group."""
