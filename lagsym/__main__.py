"""``python -m lagsym`` runs the command line."""

from .cli import run_console

if __name__ == "__main__":  # not when another process imports it as its main module
    run_console()
