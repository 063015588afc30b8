"""Errors that reach the user as one clear line (the CLI prints them without a traceback)."""

USER_ERROR_EXIT_CODE = 2  # bad input, as argparse uses for bad flags


class UserError(Exception):
    """Bad input or environment: the message names the problem and what to do about it."""


INTERRUPTED_EXIT = 130  # exit status of a command ended by Ctrl-C (128 + SIGINT, as shells report it)
