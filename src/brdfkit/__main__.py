"""``python -m brdfkit`` runs the command line (same as the ``brdfkit`` script)."""

from brdfkit.cli import run

if __name__ == "__main__":
    run()
