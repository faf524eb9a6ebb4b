"""Progress on stderr for every command that can run for seconds (issue 23).

Reference: the rule of brdfkit.cli._progress — a line on stderr when a person watches
(stderr a terminal), nothing with --json and nothing on a pipe; stdout never carries it.
A pseudo-terminal run checks the real terminal test (os.isatty), not a monkeypatch.
"""

from __future__ import annotations

import json
import os
import pty
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

import brdfkit.cli._progress as _progress
from brdfkit.cli import main

SRC = str(Path(__file__).resolve().parents[1] / "src")


def run(*args: str):
    return CliRunner().invoke(main, list(args))


def _commands(tmp_path):
    png = str(tmp_path / "s.png")
    return {
        "checking merl:nickel@abc": ["check", "merl:nickel@abc"],
        "albedo of merl:nickel@abc": ["albedo", "merl:nickel@abc", "--theta", "0,60"],
        "rendering merl:nickel@abc": ["render", "sphere", "merl:nickel@abc", "--size", "16",
                                      "--phi-l", "30", "--ambient", "0.5", "--out", png],
        "materials": ["materials", "merl:nickel@abc"],
    }


@pytest.mark.parametrize("label", ["checking merl:nickel@abc", "albedo of merl:nickel@abc",
                                   "rendering merl:nickel@abc", "materials"])
def test_long_commands_say_what_they_do_when_watched(label, monkeypatch, tmp_path):
    args = _commands(tmp_path)[label]
    monkeypatch.setattr(_progress, "stderr_is_interactive", lambda: True)
    r = run(*args)
    assert r.exit_code == 0, r.stderr
    assert r.stderr.startswith(f"{label}") and " done (" in r.stderr, r.stderr
    assert " ..." not in r.stdout and "done (" not in r.stdout
    if label.startswith("rendering"):
        return  # render sphere has no --json
    r = run(*args, "--json")
    assert r.exit_code == 0, r.stderr
    assert " ..." not in r.stderr  # nothing with --json
    json.loads(r.stdout)


def test_not_watched_nothing_on_stderr(tmp_path):
    r = run("check", "lambert")
    assert r.exit_code == 0 and r.stderr == ""


def test_progress_on_a_pseudo_terminal():
    env = {**os.environ, "PYTHONPATH": SRC}
    master, slave = pty.openpty()
    try:
        proc = subprocess.run([sys.executable, "-m", "brdfkit", "check", "lambert"],
                              stdout=subprocess.PIPE, stderr=slave, env=env, timeout=120)
        os.close(slave)
        slave = -1
        err = b""
        while True:
            try:
                chunk = os.read(master, 4096)
            except OSError:  # EIO: the terminal's other end is closed and drained
                break
            if not chunk:
                break
            err += chunk
    finally:
        if slave >= 0:
            os.close(slave)
        os.close(master)
    assert proc.returncode == 0
    assert b"checking lambert ..." in err and b"done (" in err
    assert b"checking" not in proc.stdout and b"energy:" in proc.stdout
