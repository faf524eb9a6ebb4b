"""The click group class behind ``brdfkit``: one-line errors and SIGTERM.

- Every error reaches the user as exactly one line ``brdfkit: error:
  <message>`` on stderr with exit status 2 — brdfkit's own
  :class:`~brdfkit.errors.BrdfkitError` (caught here, and only here) and
  every error click detects itself (missing option or argument, bad choice,
  value out of range, unknown command or option). ``--help`` and
  ``--version`` exit 0; ``brdfkit`` with no command prints the help (exit 2,
  as click does).
- While a command runs, SIGTERM raises :class:`Stopped` (a :class:`SystemExit`,
  status 143 = 128 + 15, the shell convention) so that ``finally``/``except
  BaseException`` blocks run — the atomic figure writer removes its temp
  file — instead of the process dying on the spot; Ctrl-C (KeyboardInterrupt)
  becomes :class:`Stopped` with status 130 = 128 + 2. Either prints one line,
  ``brdfkit: terminated`` or ``brdfkit: interrupted`` (no traceback, no click
  "Aborted!"). The previous handler is restored afterwards (the group may run
  inside another program or a test).
- Commands may be registered lazily (``lazy={name: "module:attribute"}``): the
  module is imported when the command is looked up, so a command pays only
  for its own imports.
"""

from __future__ import annotations

import contextlib
import importlib
import signal
import threading

import click

from brdfkit.errors import BrdfkitError

__all__ = ["EXIT_USAGE", "EXIT_SIGTERM", "EXIT_INTERRUPT", "BrdfkitGroup", "OneLineError",
           "Stopped", "one_line"]

#: Exit status for bad input (the same as click's usage errors).
EXIT_USAGE = 2
# Bare 'brdfkit' raises this in click >= 8.2 (shown as the help, exit 2); click 8.1, which
# pyproject still allows, prints the help and exits 0 without raising, hence the fallback.
_NO_ARGS_IS_HELP = getattr(click.exceptions, "NoArgsIsHelpError", ())

#: Exit status after SIGTERM: 128 + signal number, as a shell reports a killed process.
EXIT_SIGTERM = 128 + int(signal.SIGTERM)
#: Exit status after Ctrl-C (SIGINT), by the same convention.
EXIT_INTERRUPT = 128 + int(signal.SIGINT)


class Stopped(SystemExit):
    """The command was stopped by a signal (SIGTERM or Ctrl-C): exits with *status* after
    one line ``brdfkit: WORD[: detail]`` on stderr. A SystemExit, so ``except Exception``
    does not swallow it and ``finally`` blocks run."""

    def __init__(self, status: int, word: str, detail: str = ""):
        super().__init__(status)
        self.word, self.detail = word, detail

    @classmethod
    def interrupted(cls, detail: str = "") -> Stopped:
        """Ctrl-C: status :data:`EXIT_INTERRUPT` (130), ``brdfkit: interrupted``."""
        return cls(EXIT_INTERRUPT, "interrupted", detail)

    def line(self) -> str:
        return f"brdfkit: {self.word}" + (f": {one_line(self.detail)}" if self.detail else "")


def one_line(message: str) -> str:
    """*message* with every run of whitespace (newlines included) collapsed to one space."""
    return " ".join(str(message).split())


class OneLineError(click.ClickException):
    """An error shown as one line ``brdfkit: error: <message>`` on stderr, exit status 2."""

    exit_code = EXIT_USAGE

    def show(self, file=None) -> None:
        click.echo(f"brdfkit: error: {one_line(self.format_message())}", file=file, err=True)


def _usage_message(exc: click.UsageError) -> str:
    """click's message plus where to read the usage (the usage block itself is not shown)."""
    msg = one_line(exc.format_message())
    ctx = exc.ctx
    if ctx is not None:
        msg += f" (see '{ctx.command_path} --help')"
    return msg


def _raise_sigterm(signum, frame):  # noqa: ARG001  (signal handler signature)
    raise Stopped(EXIT_SIGTERM, "terminated")


@contextlib.contextmanager
def _sigterm_raises_systemexit():
    """Within the block, SIGTERM raises Stopped (SystemExit 143); the old handler is restored
    after."""
    if threading.current_thread() is not threading.main_thread():
        yield  # signal handlers can only be set from the main thread
        return
    previous = signal.signal(signal.SIGTERM, _raise_sigterm)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


class BrdfkitGroup(click.Group):
    """Click group reporting every error as one line (exit 2) and turning SIGTERM into SystemExit.

    Errors from the group's own arguments surface in :meth:`make_context`;
    errors of a command (its options, its callback) and unknown commands in
    :meth:`invoke`. Both convert them to :class:`OneLineError`, which click's
    ``main`` shows and exits with.
    """

    def __init__(self, *args, lazy: dict[str, str] | None = None, **kwargs):
        super().__init__(*args, **kwargs)
        #: command name -> "module:attribute", imported when the command is looked up
        #: (`brdfkit fit` need not import the renderer, SciPy's interpolators or
        #: matplotlib: ~1 s of a one-line command).
        self.lazy = dict(lazy or {})

    def list_commands(self, ctx):
        return sorted(set(super().list_commands(ctx)) | set(self.lazy))

    def get_command(self, ctx, cmd_name):
        if cmd_name not in self.commands and cmd_name in self.lazy:
            module, _, attribute = self.lazy[cmd_name].partition(":")
            self.add_command(getattr(importlib.import_module(module), attribute), cmd_name)
        return super().get_command(ctx, cmd_name)

    def make_context(self, info_name, args, parent=None, **extra):
        try:
            return super().make_context(info_name, args, parent=parent, **extra)
        except _NO_ARGS_IS_HELP:
            raise  # bare 'brdfkit': the help is the useful answer
        except click.UsageError as exc:
            raise OneLineError(_usage_message(exc)) from exc
        except KeyboardInterrupt:
            raise Stopped.interrupted() from None

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except OneLineError:
            raise
        except click.UsageError as exc:
            raise OneLineError(_usage_message(exc)) from exc
        except click.ClickException as exc:
            raise OneLineError(exc.format_message()) from exc
        except BrdfkitError as exc:
            raise OneLineError(str(exc)) from exc
        except KeyboardInterrupt:  # before click's main turns it into "Aborted!"
            raise Stopped.interrupted() from None

    def main(self, *args, **kwargs):
        with _sigterm_raises_systemexit():
            try:
                return super().main(*args, **kwargs)
            except Stopped as exc:
                click.echo(exc.line(), err=True)
                raise SystemExit(exc.code) from None
