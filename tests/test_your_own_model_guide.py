"""docs/your-own-model.md runs as printed (issue 21 §2: "a guide … whose examples a test
runs as printed").

The guide's fenced blocks are read from the markdown in order: a ```` ```python file=NAME````
block is written to NAME, the other ``python`` blocks run in one namespace, ``shell``
blocks run in a shell (``brdfkit`` the console script of this interpreter), all in one
empty directory. Each must succeed; the guide's own ``assert`` lines check the values it
states (closed forms: f at the normal, a(0) = ρ_d + ρ_s). Blocks of other languages
(``glsl``, ``text``) are illustrations and are not run.
"""

from __future__ import annotations

import os
import pathlib
import shlex
import subprocess
import sys

import pytest

GUIDE = pathlib.Path(__file__).resolve().parents[1] / "docs" / "your-own-model.md"
RUN = ("python", "shell")


def blocks(text: str) -> list[tuple[str, dict, str]]:
    """(language, {key: value} of the info string, body) of every fenced block."""
    out, lines, i = [], text.splitlines(), 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("```") and line.strip() != "```":
            info = line[3:].split()
            lang, attrs = info[0], dict(w.split("=", 1) for w in info[1:] if "=" in w)
            body = []
            i += 1
            while not lines[i].startswith("```"):
                body.append(lines[i])
                i += 1
            out.append((lang, attrs, "\n".join(body) + "\n"))
        i += 1
    return out


def test_the_guide_has_every_kind_of_block():
    found = blocks(GUIDE.read_text())
    assert any(a.get("file") == "my_model.py" for _, a, _ in found)
    kinds = {lang for lang, a, _ in found if "file" not in a}
    assert {"python", "shell"} <= kinds
    # the shell blocks name the commands of the guide's title: verdict, fit, render
    shell = "".join(b for lang, _, b in found if lang == "shell")
    for command in ("brdfkit models", "brdfkit check", "brdfkit fit", "brdfkit render"):
        assert command in shell


def test_the_guide_runs_as_printed(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    bin_dir = pathlib.Path(sys.executable).parent
    env = {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}"}
    namespace: dict = {"__name__": "__guide__"}
    for n, (lang, attrs, body) in enumerate(blocks(GUIDE.read_text())):
        if "file" in attrs:
            (tmp_path / attrs["file"]).write_text(body)
        elif lang == "python":
            exec(compile(body, f"{GUIDE.name} block {n}", "exec"), namespace)
        elif lang == "shell":
            for command in (c for c in body.splitlines() if c.strip()):
                r = subprocess.run(command, shell=True, cwd=tmp_path, env=env,
                                   capture_output=True, text=True, timeout=900)
                assert r.returncode == 0, (command, r.stdout[-2000:], r.stderr[-2000:])
                assert r.stdout or ">" in shlex.split(command), command
    assert (tmp_path / "sphere.png").stat().st_size > 0
    assert (tmp_path / "fitted.png").stat().st_size > 0
    assert (tmp_path / "fit.json").read_text().startswith("{")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(pytest.main([__file__, "-q"]))
