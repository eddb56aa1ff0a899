"""Errors a user can act on. The command line prints each as one line and exits with status 2."""


class UsageError(ValueError):
    """Bad input from the user (arguments, files, values); the message is one line."""
