"""``python -m lagsym`` runs the command line."""

from .cli import run_console

run_console()
