"""``python -m lagsym`` runs the command line."""

from .cli import run_console

if __name__ == "__main__":  # not when a worker process (lagsym.toolpath.workers) imports the main module
    run_console()
