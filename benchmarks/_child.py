"""Run any module-level function in a fresh ``spawn`` child process (benchmark helper).

:func:`run_in_child` starts a fresh process, calls ``target(**kwargs)`` there,
and returns the dict it returns (JSON-ready), or a row whose ``status`` says
why there is none (exception, timeout, crash).  :func:`_common.run_case` runs
the map methods of :data:`_common.METHODS` through it; the scripts of the
"uses" layer (registration.py, landmark_speed.py, p_harmonic.py, precision.py)
pass their own measuring functions.  Peak RSS is measured by the target itself
(:class:`_common.Clock`), so a fresh process per call is what makes it that
call's own peak."""

import multiprocessing as mp
import sys
import time
import traceback

from _common import BENCH_DIR, _one_line, json_ready


def _child_main(conn, target, kwargs):
    try:
        sys.path.insert(0, str(BENCH_DIR))
        out = dict(target(**kwargs))
        out.setdefault("status", "ok")
    except Exception as exc:  # reported in the row, not fatal
        out = dict(status=f"failed: {type(exc).__name__}: {_one_line(exc)}",
                   traceback=traceback.format_exc(limit=10))
    conn.send(json_ready(out))
    conn.close()


def run_in_child(target, kwargs, timeout=600.0):
    """``target(**kwargs)`` in a fresh ``spawn`` child process, bounded by ``timeout`` seconds.

    Parameters
    ----------
    target : callable
        A module-level function (picklable by reference) returning a dict.
    kwargs : dict
        Its keyword arguments (picklable; pass file paths, not big arrays).
    timeout : float
        Wall-clock limit of the whole child; on expiry it is killed.

    Returns
    -------
    dict
        What ``target`` returned, with ``status`` ``"ok"`` unless it set one;
        or ``status`` ``"failed: ..."`` (exception, with ``traceback``; or the
        child died, e.g. killed for memory) or ``"timeout"``.  ``wall_seconds``
        is the child's whole life (start-up, loading, the calls, the metrics).
    """
    ctx = mp.get_context("spawn")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child_main, args=(send, target, dict(kwargs)), daemon=True)
    t0 = time.perf_counter()
    proc.start()
    send.close()
    out = None
    if recv.poll(timeout):
        try:
            out = recv.recv()
        except EOFError:
            out = None
    elapsed = time.perf_counter() - t0
    if out is None and proc.is_alive():
        proc.kill()
        proc.join()
        out = dict(status="timeout", notes=[f"killed after {timeout:g} s"])
    else:
        proc.join(30)
        if proc.is_alive():
            proc.kill()
            proc.join()
        if out is None:
            code = proc.exitcode
            why = (f"killed by signal {-code} (out of memory?)" if code and code < 0
                   else f"exit code {code}")
            out = dict(status=f"failed: child process died ({why})")
    recv.close()
    out["wall_seconds"] = elapsed
    return out
