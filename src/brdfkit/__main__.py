"""``python -m brdfkit`` runs the command line (same as the ``brdfkit`` script)."""

from brdfkit.cli import main

if __name__ == "__main__":
    main(prog_name="brdfkit")
