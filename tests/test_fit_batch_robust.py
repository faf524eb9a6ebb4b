"""Batches that never lose or hide rows (issue 19): one writer per output, failed fits
exit non-zero, rows checked on resume, foreign files refused, workers capped at the CPUs
and dying with the batch, stale temporary files removed.

The job function is test_fit_batch's (a closed-form row: ``value = len(model) * 10 +
len(target)``), so expected rows are known independently of the batch machinery; the
command-line cases run real fits of surrogate materials.
"""

from __future__ import annotations

import contextlib
import csv
import multiprocessing
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner
from test_fit_batch import JOBS, closed_form, job_fn
from test_fit_distributed import _until as until

import brdfkit
from brdfkit.cli import main
from brdfkit.errors import BrdfkitError
from brdfkit.fitting.batch import (
    STATUS_ERROR,
    STATUS_OK,
    Job,
    read_checked,
    run_batch,
    useful_workers,
    write_rows,
)

HERE = Path(__file__).resolve().parent
#: The brdfkit under test (the worktree's, or the one PYTHONPATH names) for subprocesses.
SRC = str(Path(brdfkit.__file__).resolve().parents[1])
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([SRC, str(HERE),
                                                    os.environ.get("PYTHONPATH", "")])}
#: Bound of every wait on another process (s): it imports brdfkit (and Numba) first.
WAIT_S = 60.0


def _until(what, check, timeout=WAIT_S, every=0.05):
    return until(what, check, timeout, every)


def _kill_group(proc) -> None:
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGKILL)
    with contextlib.suppress(subprocess.TimeoutExpired):
        proc.wait(timeout=10)


def _one_error_line(result, status=2) -> str:
    assert result.exit_code == status, (result.exit_code, result.output, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("brdfkit: error: "), result.stderr
    assert "Traceback" not in result.output + result.stderr
    return lines[0]


# --------------------------------------------------------------------------- one writer
_SLOW_BATCH = """
import sys
from test_fit_batch import JOBS, job_fn
from brdfkit.fitting.batch import Job, run_batch
jobs = [Job(j.model, j.target, options=(("delay", 0.4),)) for j in JOBS]
run_batch(jobs, out=sys.argv[1], run_job=job_fn)
"""


def test_a_second_writer_is_refused_and_no_row_is_lost(tmp_path):
    """Before: both batches ran, both said all their rows were written, and the file kept
    one batch's rows (each rewrote the file from what it had read)."""
    out = tmp_path / "fits.csv"
    first = subprocess.Popen([sys.executable, "-c", _SLOW_BATCH, str(out)], env=ENV,
                             start_new_session=True)
    try:
        _until("the first batch's first row", lambda: out.exists() and read_checked(out)[0])
        other = [Job("lambert", "merl:x")]
        with pytest.raises(BrdfkitError, match=rf"--out '{out}' is being written by another "
                                               rf"batch \(process {first.pid}\)"):
            run_batch(other, out=out, run_job=job_fn)
        line = _one_error_line(CliRunner().invoke(
            main, ["fit", "lambert", "--to", "merl:nickel@abc", "--out", str(out)]))
        assert f"process {first.pid}" in line and "choose another --out" in line
        assert first.wait(timeout=WAIT_S) == 0
    finally:
        _kill_group(first)
    rows, invalid = read_checked(out)
    assert not invalid and {(r["model"], r["target"]) for r in rows} == \
        {(j.model, j.target) for j in JOBS}
    rep = run_batch(other, out=out, run_job=job_fn)  # the lock is free again
    assert rep.done == 1 and len(read_checked(out)[0]) == len(JOBS) + 1
    assert not (tmp_path / ".fits.csv.lock").exists()


def test_the_lock_of_a_killed_batch_does_not_block_the_next(tmp_path):
    """A SIGKILLed holder leaves its lock file; the kernel dropped the lock with it."""
    out = tmp_path / "fits.csv"
    holder = subprocess.Popen([sys.executable, "-c", _SLOW_BATCH, str(out)], env=ENV,
                              start_new_session=True)
    try:
        _until("the first row", lambda: out.exists() and read_checked(out)[0])
    finally:
        _kill_group(holder)
    assert (tmp_path / ".fits.csv.lock").exists()
    rep = run_batch(JOBS, out=out, run_job=job_fn)
    assert rep.skipped >= 1 and rep.skipped + rep.done == len(JOBS)


# --------------------------------------------------------------------------- exit status
def _truncated_binary(path: Path) -> Path:
    """A MERL .binary cut short: the header (90, 90, 180) and 10 of 4,374,000 doubles
    (layout: brdfkit.data.merl's docstring, after Matusik et al. 2003)."""
    import numpy as np

    path.write_bytes(np.array([90, 90, 180], "<i4").tobytes() + np.zeros(10, "<f8").tobytes())
    return path


def test_failed_fits_exit_1_with_the_count_and_first_reasons(tmp_path):
    """Before: status 0 whatever failed ('1 failed, of 1')."""
    out = tmp_path / "fits.csv"
    cut = _truncated_binary(tmp_path / "cut.binary")
    args = ["fit", "lambert", "--to", "merl:nickel@abc", "--to", "merl:nosuch", "--to",
            str(cut), "--out", str(out)]
    result = CliRunner().invoke(main, args)
    line = _one_error_line(result, status=1)
    assert line.startswith("brdfkit: error: 2 of 3 fits failed (merl:nosuch (lambert): ")
    assert f"{cut} (lambert): " in line and str(out) in line
    assert "3 fitted now, 0 already there, 2 failed, of 3" in result.stdout
    rows = {r["target"]: r for r in read_checked(out)[0]}
    assert rows["merl:nickel@abc"]["status"] == STATUS_OK
    assert rows["merl:nosuch"]["status"] == rows[str(cut)]["status"] == STATUS_ERROR
    # the re-run retries only the failed ones, and fails again the same way
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 1 and "1 already there" in result.stdout
    # a batch without failures: 0
    ok = CliRunner().invoke(main, ["fit", "lambert", "--to", "merl:nickel@abc", "--out",
                                   str(tmp_path / "ok.csv")])
    assert ok.exit_code == 0 and ok.stderr == "", ok.stderr


# --------------------------------------------------------------------------- resume
def _written(path, rows):
    write_rows(path, rows)
    return path.read_text(encoding="utf-8")


def _fit_like_rows():
    """Rows as fit_row writes them (params and at_bounds JSON) for JOBS[:3]."""
    return [{"model": j.model, "target": j.target, "loss": j.loss, "procedure": j.procedure,
             "status": STATUS_OK, "value": closed_form(j),
             "params": '{"rho_d": [0.25, 0.5, 0.75]}', "at_bounds": "[]"} for j in JOBS[:3]]


def test_resume_refits_a_row_cut_mid_way_and_drops_junk(tmp_path):
    """Before: a row cut inside its params was kept as ok and never refitted; junk and
    NUL-prefixed lines were copied into the rewritten file."""
    out = tmp_path / "fits.csv"
    text = _written(out, _fit_like_rows())
    cut_at = text.rindex('"{""rho_d"": [0.25') + len('"{""rho_d"": [0.25')
    text = text[:cut_at]  # the last row ends inside its params (a crash of another writer)
    lines = text.split("\n")
    lines.insert(2, "\x00\x00\x00\x00phong,merl:zz,l1,auto,ok,1,{},[]")
    lines.insert(3, "junk without the columns")
    bad_json = lines[1].replace('"{""rho_d"": [0.25, 0.5, 0.75]}"', '"{""rho_d"": [0.2"')
    lines.insert(4, bad_json.replace("merl:a", "merl:zzz"))
    lines.insert(5, lines[1].replace(",ok,", ",okay,").replace("merl:a", "merl:zzzz"))
    out.write_text("\n".join(lines), encoding="utf-8")
    notes = []
    rep = run_batch(JOBS[:3], out=out, run_job=job_fn, notice=notes.append)
    # JOBS[0], JOBS[1] valid and skipped; JOBS[2] (the cut row) run again
    assert (rep.total, rep.skipped, rep.done) == (3, 2, 1)
    assert len(rep.invalid) == 5 and len(notes) == 1
    assert "5 invalid row(s) left out" in notes[0] and "NUL byte" in notes[0]
    whys = " | ".join(rep.invalid)
    assert "line 3: a NUL byte in model" in whys
    assert "line 4: its number of fields differs" in whys
    assert "line 5: params is not JSON" in whys
    assert "line 6: status 'okay'" in whys
    assert "line 8: its number of fields differs" in whys  # the cut row
    raw = out.read_bytes()
    assert b"\x00" not in raw and b"junk" not in raw and b"okay" not in raw
    rows, invalid = read_checked(out)
    assert not invalid and len(rows) == 3
    assert {(r["model"], r["target"]) for r in rows} == {(j.model, j.target) for j in JOBS[:3]}


def test_invalid_rows_are_dropped_even_when_nothing_is_left_to_run(tmp_path):
    out = tmp_path / "fits.csv"
    text = _written(out, _fit_like_rows())
    out.write_text(text + "\x00junk\n", encoding="utf-8")
    notes = []
    rep = run_batch(JOBS[:3], out=out, run_job=job_fn, notice=notes.append)
    assert rep.done == 0 and len(rep.invalid) == 1 and notes
    assert out.read_text(encoding="utf-8") == text


def test_a_byte_order_mark_is_no_foreign_file(tmp_path):
    """A spreadsheet saving the CSV as 'UTF-8 with BOM' puts U+FEFF before the header."""
    out = tmp_path / "fits.csv"
    text = _written(out, _fit_like_rows())
    out.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    rep = run_batch(JOBS[:3], out=out, run_job=job_fn)
    assert (rep.skipped, rep.done, rep.invalid) == (3, 0, [])


def weird_status(job):
    return {"status": "fine, thanks"}


def test_a_row_with_a_status_of_its_own_is_an_error_row(tmp_path):
    """Written as it was, it would be an invalid row on every resume."""
    out = tmp_path / "fits.csv"
    rep = run_batch(JOBS[:1], out=out, run_job=weird_status)
    assert rep.failed == 1 and "returned status 'fine, thanks'" in rep.failures[0]
    assert read_checked(out)[0][0]["status"] == STATUS_ERROR


def test_a_foreign_file_is_refused_in_one_line(tmp_path):
    """Before: UnicodeDecodeError (a traceback) for a binary or Parquet file named .csv."""
    binary = tmp_path / "binary.csv"
    binary.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(BrdfkitError, match=r"binary\.csv: not a brdfkit batch file \(not UTF-8 "
                                           r"text: byte 0x80 at offset 128\)"):
        run_batch(JOBS, out=binary, run_job=job_fn)
    line = _one_error_line(CliRunner().invoke(
        main, ["fit", "lambert", "--to", "merl:nickel@abc", "--out", str(binary)]))
    assert "not UTF-8 text" in line and str(binary) in line
    pq = pytest.importorskip("pyarrow.parquet")
    pa = pytest.importorskip("pyarrow")
    parquet = tmp_path / "table.csv"
    pq.write_table(pa.table({"model": ["x"], "target": ["y"]}), parquet)
    with pytest.raises(BrdfkitError, match=r"table\.csv: not a brdfkit batch file \(it is a "
                                           r"Parquet file; name it \.parquet\)"):
        run_batch(JOBS, out=parquet, run_job=job_fn)
    assert binary.read_bytes() == bytes(range(256)) * 4  # never overwritten


def test_parquet_rows_are_checked_too(tmp_path):
    pytest.importorskip("pyarrow")
    out = tmp_path / "fits.parquet"
    rows = _fit_like_rows()
    rows[1]["status"] = "weird"
    rows[2]["params"] = '{"rho_d": [0.2'
    write_rows(out, rows)
    valid, invalid = read_checked(out)
    assert [r["target"] for r in valid] == [JOBS[0].target]
    assert invalid == ["row 2: status 'weird' is none of ok, error, not-converged",
                       """row 3: params is not JSON ('{"rho_d": [0.2'...)"""]
    rep = run_batch(JOBS[:3], out=out, run_job=job_fn, notice=lambda line: None)
    assert (rep.skipped, rep.done) == (1, 2) and not read_checked(out)[1]


# --------------------------------------------------------------------------- workers
def test_workers_are_capped_at_the_cpus(tmp_path):
    """--workers 100: before, one process per job was started (100 on 2 cores for a
    large batch). Now at most one per CPU, said in one notice."""
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    jobs = [Job("phong", f"merl:{'a' * (k + 1)}", options=(("delay", 0.3),))
            for k in range(cpus + 2)]
    seen = []

    def progress(done, total, label):
        if done:
            seen.append(len(multiprocessing.active_children()))

    notes = []
    rep = run_batch(jobs, out=tmp_path / "fits.csv", run_job=job_fn, workers=100,
                    progress=progress, notice=notes.append)
    assert max(seen) <= cpus, seen  # worker processes alive as the rows came in
    assert rep.success and rep.workers == cpus
    assert notes == [f"--workers 100 capped at {cpus}: this machine has {cpus} CPU(s) for this "
                     "process, and more processes than CPUs only compete for them"]
    rows = read_checked(tmp_path / "fits.csv")[0]
    assert len({r["pid"] for r in rows}) <= cpus
    assert useful_workers(100, 1) == (1, "")  # one job: one process, nothing to say


def _descendants(pid: int) -> list[int]:
    """Every process below *pid* (from /proc: each task's parent)."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            with contextlib.suppress(OSError, IndexError, ValueError):
                stat = Path(f"/proc/{entry}/stat").read_text()
                ppid = int(stat.rsplit(")", 1)[1].split()[1])
                children.setdefault(ppid, []).append(int(entry))
    out, todo = [], [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            out.append(c)
            todo.append(c)
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"  # a zombie has died (its parent, PID 1 here, reaps it)


@pytest.mark.skipif(not sys.platform.startswith("linux") or len(os.sched_getaffinity(0)) < 2,
                    reason="reads /proc; needs two CPUs for worker processes")
def test_workers_die_with_a_killed_batch(tmp_path):
    """SIGKILL of the batch's process: before, its worker processes and multiprocessing's
    resource tracker slept on under PID 1 for ever."""
    proc = subprocess.Popen([sys.executable, "-m", "brdfkit", "fit", "lambert", "--to",
                             "merl:nickel@abc", "--to", "merl:violet-rubber@abc", "--to",
                             "merl:gold-paint@abc", "--out", str(tmp_path / "fits.csv"),
                             "--workers", "2"], env=ENV, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        # the resource tracker and two workers
        kids = _until("the workers", lambda: len(d := _descendants(proc.pid)) >= 3 and d)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=10)
        _until("the workers' end", lambda: not any(_alive(k) for k in kids), timeout=15)
    finally:
        _kill_group(proc)  # the group: whatever is left, so that no test leaves it


# --------------------------------------------------------------------------- temp files
_KILLED_WRITER = """
import sys, time
from brdfkit._io import write_atomic
def write(fh):
    fh.write(b"half a file")
    fh.flush()
    print("writing", flush=True)
    time.sleep(60)
write_atomic(sys.argv[1], write)
"""


def test_stale_temp_files_of_dead_writers_are_removed(tmp_path):
    """A writer SIGKILLed mid-write leaves its .brdfkit-* temp file; before, no later run
    removed it. Now the next write into the directory does — only our own pattern, only
    files whose writer is gone (or, untagged by a pid, an hour old)."""
    writer = subprocess.Popen([sys.executable, "-c", _KILLED_WRITER, str(tmp_path / "r.npy")],
                              env=ENV, stdout=subprocess.PIPE, text=True,
                              start_new_session=True)
    try:
        assert writer.stdout.readline().strip() == "writing"
        os.kill(writer.pid, signal.SIGKILL)
        writer.wait(timeout=10)
    finally:
        _kill_group(writer)
    left = [p.name for p in tmp_path.iterdir() if p.name.startswith(".brdfkit-")]
    assert len(left) == 1, left  # the killed writer's (.brdfkit-<its pid>-XXXXXXXX.npy)
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        keep = [f".brdfkit-{live.pid}-abcdefgh.csv",  # its writer lives
                ".brdfkit-ijklmnop.npy",              # untagged, fresh
                ".brdfkit-notes.txt", "fits-old.csv", ".brdfkit-12-abc.csv"]  # not ours
        old = tmp_path / ".brdfkit-qrstuvwx.npy"      # untagged, two hours old
        for name in keep:
            (tmp_path / name).write_text("x")
        old.write_text("x")
        two_hours_ago = time.time() - 7200
        os.utime(old, (two_hours_ago, two_hours_ago))
        run_batch(JOBS[:1], out=tmp_path / "fits.csv", run_job=job_fn)
        names = {p.name for p in tmp_path.iterdir()}
    finally:
        live.kill()
        live.wait(timeout=10)
    assert left[0] not in names and old.name not in names
    assert set(keep) <= names and "fits.csv" in names


def test_the_rows_stay_readable_as_plain_csv(tmp_path):
    """The checks change nothing in what is written: an ordinary CSV reader reads it."""
    out = tmp_path / "fits.csv"
    run_batch(JOBS, out=out, run_job=job_fn)
    with open(out, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == len(JOBS) and all(r["status"] == STATUS_OK for r in rows)
