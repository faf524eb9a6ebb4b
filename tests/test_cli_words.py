"""The command line's words are documented in one table, docs/cli.md (issue 20), and the
table cannot drift: click's command tree is walked here and every option and argument of
every command must be a row naming that command, every row's command must have the word,
and the rows under "Old spellings" are exactly the hidden (deprecated) options."""

from __future__ import annotations

import pathlib
import re

import click
import pytest

from brdfkit.cli import main

DOC = pathlib.Path(__file__).resolve().parents[1] / "docs" / "cli.md"


def commands():
    """(path, command) of every leaf command, e.g. ("render sphere", <Command>)."""
    ctx = click.Context(main)

    def walk(cmd, path):
        if isinstance(cmd, click.Group):
            for name in cmd.list_commands(ctx):
                yield from walk(cmd.get_command(ctx, name), [*path, name])
        else:
            yield " ".join(path), cmd
    return list(walk(main, []))


def word_of(param: click.Parameter) -> str:
    """An option by its longest name (--param for -p/--param), an argument by its metavar."""
    if isinstance(param, click.Argument):
        return param.metavar or param.human_readable_name
    return max(param.opts, key=len)


def in_code():
    """{(command, word): hidden?} from the command tree (--help left out)."""
    out = {}
    for path, cmd in commands():
        for p in cmd.params:
            if isinstance(p, click.Option) and p.name == "help":
                continue
            out[(path, word_of(p))] = bool(getattr(p, "hidden", False))
    return out


def in_doc():
    """{(command, word): in the 'Old spellings' table?} from docs/cli.md's tables."""
    out, old = {}, False
    for line in DOC.read_text(encoding="utf-8").splitlines():
        if line.startswith("## "):
            old = line.strip() == "## Old spellings"
        if not line.startswith("| `"):
            continue
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]
        spans = [s.replace("\\|", "|") for s in re.findall(r"`([^`]+)`", cells[0])]
        options = [s for s in spans if s.startswith("-")]
        word = max(options, key=len) if options else spans[0]
        for cmd in re.findall(r"`([^`]+)`", cells[-1]):
            assert (cmd, word) not in out, f"docs/cli.md lists {word} of {cmd} twice"
            out[(cmd, word)] = old
    return out


def test_every_word_of_every_command_is_in_the_table_and_nothing_else():
    code, doc = in_code(), in_doc()
    missing = sorted(set(code) - set(doc))
    extra = sorted(set(doc) - set(code))
    assert not missing, f"options/arguments not in docs/cli.md: {missing}"
    assert not extra, f"docs/cli.md rows whose command lacks the word: {extra}"


def test_old_spellings_are_the_hidden_options():
    code, doc = in_code(), in_doc()
    assert {k for k, hidden in code.items() if hidden} == {k for k, old in doc.items() if old}


@pytest.mark.parametrize("word", ["--param", "--compensate", "--pump", "--times"])
def test_every_command_acting_on_a_model_takes_its_words(word):
    # one way to describe a model: every command with a model argument takes its words
    code = in_code()
    with_model = {c for c, w in code if w in ("MODEL", "[MODEL]", "MODEL...", "[MODEL]...")}
    assert with_model >= {"albedo", "check", "eval", "export", "render sphere", "figure",
                          "fit", "explore", "table2"}
    lacking = sorted(c for c in with_model - {"table2"} if (c, word) not in code)
    assert not lacking, f"{word} missing on {lacking}"


def test_the_readme_links_the_table():
    readme = (DOC.parents[1] / "README.md").read_text(encoding="utf-8")
    assert "docs/cli.md" in readme
