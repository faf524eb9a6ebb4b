"""
A batch on a Dask distributed cluster (``run_batch(..., scheduler=...)``)
=========================================================================

- **The address is checked before anything connects**: ``[tcp://]HOST:PORT`` (or
  another scheme of Dask's, ``tls://``, ``ws://``, ``inproc://``…) with a port from 1 to
  65535; anything else is one error naming the address and the form expected.
- **Connecting is bounded**: a probe opens Dask's handshake and asks the scheduler who it
  is (its ``identity``) within :data:`CONNECT_TIMEOUT_S`, in a thread of its own. Dask's
  own connect bounds the TCP connection but not the handshake's reply, so a server that
  accepts the connection and never answers as Dask would (an HTTP server, say) held the
  ``Client`` for ever; a process that answers but is no scheduler is refused too.
- **The client is this batch's own** (``set_as_default=False``): the completion loop
  runs on its event loop (``as_completed(loop=client.loop)``) and never looks up a
  default client.
- **A scheduler that goes away** cancels every pending future (Dask's client does that
  when it loses the connection): the batch stops with one error saying how many rows are
  on disk; a re-run resumes. Dask's own log lines about the lost connection are held back
  while the batch's client runs (the error says it).
- A worker that dies mid-task is Dask's business: the scheduler runs the task again on
  another worker (or on the one the nanny restarts); its row is written once.

Public objects: none (:func:`run_dask` is :func:`brdfkit.fitting.batch.run_batch`'s).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import threading
from collections.abc import Callable

from brdfkit.errors import BrdfkitError

__all__ = ["run_dask", "check_address", "CONNECT_TIMEOUT_S"]

#: Seconds to connect to a scheduler and hear it answer as one. Dask's default is 30 s,
#: sized for clusters whose scheduler is still starting; a batch is started against a
#: running scheduler, and 10 s is ample for a handshake across a data centre while a
#: wrong address fails within a coffee sip.
CONNECT_TIMEOUT_S = 10.0
#: Extra seconds the probe's thread is given beyond the timeout to return its verdict.
_PROBE_GRACE_S = 5.0
_FORM = "[tcp://]HOST:PORT, e.g. tcp://127.0.0.1:8786 (what 'dask scheduler' prints)"


def _distributed():
    try:
        import distributed
    except ImportError:
        raise BrdfkitError("--scheduler needs Dask distributed: pip install 'brdfkit[batch]' "
                           "(or pip install distributed)") from None
    return distributed


def check_address(address) -> str:
    """*address* as Dask writes it (``tcp://HOST:PORT``), or a BrdfkitError naming it."""
    _distributed()
    from distributed.comm.addressing import parse_address, parse_host_port, unparse_address
    from distributed.comm.registry import backends

    text = str(address).strip()
    bad = f"--scheduler {str(address)!r} is not a Dask scheduler address; expected {_FORM}"
    if not text or any(c.isspace() for c in text):
        raise BrdfkitError(bad)
    try:
        scheme, loc = parse_address(text, strict=False)
    except ValueError:
        raise BrdfkitError(bad) from None
    if scheme not in backends:
        raise BrdfkitError(f"{bad}; the scheme {scheme!r} is none of Dask's "
                           f"({', '.join(sorted(backends))})")
    if scheme != "inproc":
        try:
            host, port = parse_host_port(loc)
        except ValueError:
            raise BrdfkitError(f"{bad}; the port is missing or not a number") from None
        if not (host and 1 <= int(port) <= 65535):
            raise BrdfkitError(f"{bad}; {'the port must be 1 to 65535' if host else 'no host'}"
                               f", got {loc!r}")
    return unparse_address(scheme, loc)


async def _identity(address: str, timeout: float) -> dict:
    from distributed.core import rpc
    from distributed.security import Security

    # the TLS settings a Client would take from Dask's configuration
    args = Security().get_connection_args("client")
    async with rpc(address, timeout=timeout, connection_args=args) as scheduler:
        return await scheduler.identity()


def _probe(address: str, timeout: float = CONNECT_TIMEOUT_S) -> None:
    """Connect to *address* and hear it answer as a Dask scheduler within *timeout*
    seconds, in a thread with its own event loop (the caller may be inside one)."""
    verdict: dict = {}

    def run() -> None:
        try:
            verdict["info"] = asyncio.run(asyncio.wait_for(_identity(address, timeout),
                                                           timeout))
        except Exception as exc:  # noqa: BLE001 - carried out of the thread, reported below
            verdict["error"] = exc

    thread = threading.Thread(target=run, name="brdfkit-dask-probe", daemon=True)
    thread.start()
    thread.join(timeout + _PROBE_GRACE_S)
    exc = verdict.get("error")
    if "info" not in verdict:
        if exc is None or isinstance(exc, asyncio.TimeoutError | TimeoutError):
            why = f"no answer as a Dask scheduler within {timeout:g} s"
        else:
            why = " ".join(str(exc).split()) or type(exc).__name__
        raise BrdfkitError(f"--scheduler {address}: cannot connect to a Dask scheduler "
                           f"({why}); start one with 'dask scheduler' or check the address")
    info = verdict["info"]
    if not (isinstance(info, dict) and info.get("type") == "Scheduler"):
        kind = info.get("type") if isinstance(info, dict) else type(info).__name__
        raise BrdfkitError(f"--scheduler {address}: answers as a Dask {kind}, not a "
                           "scheduler; give the scheduler's address")


@contextlib.contextmanager
def _quiet_dask_logs():
    """Hold back Dask's log lines (the lost-connection tracebacks) for the block: every
    ``distributed`` logger is disabled (Dask's config gives some their own levels, so
    the parent's level alone does not reach them), then restored."""
    manager = logging.getLogger().manager
    names = ["distributed", *(n for n in list(manager.loggerDict)
                              if n.startswith("distributed."))]
    loggers = [logging.getLogger(n) for n in names]
    before = [lg.disabled for lg in loggers]
    for lg in loggers:
        lg.disabled = True
    try:
        yield
    finally:
        for lg, was in zip(loggers, before, strict=True):
            lg.disabled = was


def _client(scheduler):
    """(client, owned) for *scheduler*: an address (checked, probed) or a Client /
    cluster object."""
    distributed = _distributed()
    if isinstance(scheduler, distributed.Client):
        return scheduler, False
    if not isinstance(scheduler, str):  # a cluster object (LocalCluster, …)
        return distributed.Client(scheduler, set_as_default=False), True
    address = check_address(scheduler)
    _probe(address)
    try:
        client = distributed.Client(address, timeout=f"{CONNECT_TIMEOUT_S}s",
                                    set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise BrdfkitError(f"--scheduler {address}: cannot connect to a Dask scheduler "
                           f"({' '.join(str(exc).split())}); start one with 'dask scheduler' "
                           "or check the address") from None
    return client, True


def run_dask(todo, *, run_job, scheduler, retries: int, record: Callable[[dict], None],
             safe: Callable, error_row: Callable[..., dict], where: Callable[[], str],
             say: Callable[[str], None]) -> None:
    """Run *todo* on the cluster, ``record(row)`` as each finishes (module docstring).
    ``where()`` says how many rows are on disk (for the error when the scheduler goes);
    ``say(line)`` tells the user what they may not expect (a scheduler without workers)."""
    from distributed import as_completed

    client, own = _client(scheduler)
    address = getattr(client.scheduler, "address", None) or str(scheduler)
    with contextlib.suppress(OSError, TimeoutError):  # a courtesy: the batch runs anyway
        if todo and not client.scheduler_info().get("workers"):
            say(f"the Dask scheduler {address} has no worker yet: the jobs wait for one "
                "('dask worker ADDRESS' starts one; Ctrl-C stops, keeping finished rows)")
    quiet = _quiet_dask_logs() if own else contextlib.nullcontext()
    with quiet:
        try:
            job_of = {client.submit(safe, run_job, j, pure=False, retries=retries,
                                    key=f"brdfkit-fit-{'|'.join(j.key)}-{os.getpid()}-{k}"): j
                      for k, j in enumerate(todo)}
            futures = list(job_of)
            lost = False
            try:
                for fut, row in as_completed(futures, loop=client.loop, with_results=True,
                                             raise_errors=False):
                    if fut.status == "cancelled":  # the scheduler went (or cancelled it)
                        lost = True
                        break
                    if fut.status == "error":  # e.g. KilledWorker after the allowed retries
                        row = error_row(job_of[fut], f"dask: {fut.exception()}")
                    record(row)
            except BaseException:
                with contextlib.suppress(OSError, TimeoutError, RuntimeError):
                    client.cancel(futures)
                raise
            if lost:
                raise BrdfkitError(f"the Dask scheduler {address} went away (or cancelled "
                                   f"the jobs): {where()}; restart it and re-run the same "
                                   "command to resume")
        finally:
            if own:
                with contextlib.suppress(OSError, TimeoutError, RuntimeError):
                    client.close(timeout=CONNECT_TIMEOUT_S)
