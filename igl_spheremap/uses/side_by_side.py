"""Independent stages of a use run side by side in worker processes.

A map between two surfaces starts with work that does not depend on itself: each
surface's conformal map and the functional map's pairs.  Algorithm 1 runs in one
thread (its sparse solves and per-face loops gain nothing from BLAS threads, see
:attr:`igl_spheremap.MapOptions.blas_threads`; only the Newton metric's per-face set-up is
split over threads, :func:`igl_spheremap.optimize.face_hessians.projected_tangent_hessians`),
so on a machine with several cores these jobs finish sooner in separate processes than one
after the other.
"""

import multiprocessing
import pickle
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np

#: Worker processes of :func:`igl_spheremap.uses.registration.surface_map` by default: its
#: three independent first jobs (two conformal maps, the functional map's pairs).
DEFAULT_WORKERS = 3

#: Why a pool may not start, when the jobs then run in this process: a daemonic process (a
#: ``multiprocessing`` or Dask worker) may not have children (AssertionError), a system may
#: lack processes or semaphores (OSError).
NO_POOL = (AssertionError, OSError)


def side_by_side(jobs, workers):
    """Run independent jobs, the first in this process and the others in worker processes.

    Parameters
    ----------
    jobs : list of tuple
        ``(function, *args)``: module-level functions and their arguments (picklable).
    workers : int
        Largest number of processes working at once, this one included: ``jobs[0]`` runs
        here while up to ``workers - 1`` child processes, forked from this one, run the
        others.  ``1`` runs every job here, one after the other; so do jobs that do not
        pickle, any platform but Linux and a pool that cannot start (:data:`NO_POOL`), with
        the same results.

    Returns
    -------
    list
        ``function(*args)`` of each job, in the order of ``jobs``.

    Raises
    ------
    ValueError
        If ``workers`` is not an integer >= 1.
    Exception
        Whatever a job raises, re-raised here.
    """
    workers = checked_workers(workers)
    context = _fork_context()
    if workers == 1 or len(jobs) < 2 or context is None or not _picklable(jobs[1:]):
        return [_run(job) for job in jobs]
    pool = None
    try:
        pool = ProcessPoolExecutor(min(workers - 1, len(jobs) - 1), mp_context=context)
        futures = [pool.submit(*job) for job in jobs[1:]]
    except NO_POOL:
        if pool is not None:
            pool.shutdown(wait=False, cancel_futures=True)
        return [_run(job) for job in jobs]
    with pool:
        first = _run(jobs[0])
        return [first] + [f.result() for f in futures]


class Background:
    """One job started in a worker process now, its result taken later (:meth:`result`).

    Beside :func:`side_by_side`, for a job whose result is needed only after other work
    (the functional map's pairs, which the alignment needs after both conformal maps and
    after the starts that do without them).  With ``workers == 1``, where no process can be
    forked (:data:`NO_POOL`), or for a job that does not pickle, the job runs in this
    process when its result is first asked for, with the same result.

    Parameters
    ----------
    job : tuple
        ``(function, *args)``, as in :func:`side_by_side`.
    workers : int
        As in :func:`side_by_side`: 1 runs the job here.
    """

    def __init__(self, job, workers):
        self.job, self.process, self.conn, self.value = job, None, None, None
        context = _fork_context()
        if checked_workers(workers) == 1 or context is None or not _picklable([job]):
            return
        receive, send = context.Pipe(duplex=False)
        self.process = _started(context, _send_result, (send, job), [receive], [send])
        if self.process is not None:
            self.conn = receive

    def done(self):
        """Whether the result is there without waiting (bool); a job that runs here is not."""
        return self.value is not None or (self.conn is not None and self.conn.poll())

    def result(self):
        """The job's result, waiting for the worker (or running the job here) if need be.

        Raises
        ------
        Exception
            Whatever the job raises; RuntimeError if the worker died without an answer.
        """
        if self.value is None:
            if self.conn is None:
                self.value = (_run(self.job),)
            else:
                try:
                    ok, value = self.conn.recv()
                except EOFError:
                    raise RuntimeError("the worker process ended without a result") from None
                finally:
                    self.close()
                if not ok:
                    raise value
                self.value = (value,)
        return self.value[0]

    def close(self):
        """End the worker process (a job still running is stopped)."""
        if self.conn is not None:
            self.conn.close()
            self.conn = None
        self.process = _stopped(self.process)


class Chain:
    """``state = step(state, item)`` for each item sent, in a worker process while this one
    goes on; the last state taken later (:meth:`result`).

    For a chain of calls whose inputs this process produces one by one and whose output it
    needs only at the end (the fine map following each accepted step of a coarse distortion
    stage, :func:`igl_spheremap.uses.coarse_to_fine.coarse_stage`): the steps run beside the
    work that produces the items, in the order sent.  Where no process can start (as for
    :class:`Background`) each step runs here when its item is sent, with the same result.
    The worker is forked with ``step`` and ``state``; the items and the result are pickled.

    Parameters
    ----------
    step : callable
        ``step(state, item)`` -> the next state.
    state : object
        The state before the first item.
    workers : int
        As in :func:`side_by_side`: 1 runs every step here.
    """

    def __init__(self, step, state, workers):
        self.step, self.state, self.process, self.items, self.out = step, state, None, None, None
        context = _fork_context()
        if checked_workers(workers) == 1 or context is None:
            return
        items_in, items_out = context.Pipe(duplex=False)
        result_in, result_out = context.Pipe(duplex=False)
        self.process = _started(context, _chain_steps, (items_in, result_out, step, state),
                                [items_out, result_in], [items_in, result_out])
        if self.process is not None:
            self.items, self.out = items_out, result_in

    def send(self, item):
        """Add ``item`` to the chain (its step runs here at once when no worker runs).

        Raises
        ------
        RuntimeError
            If the worker process has ended.
        """
        if self.items is None:
            self.state = self.step(self.state, item)
            return
        try:
            self.items.send((True, item))
        except BrokenPipeError:
            self.close()
            raise RuntimeError("the worker process ended without a result") from None

    def result(self):
        """The state after every item sent, waiting for the worker if need be.

        Raises
        ------
        Exception
            Whatever a step raised; RuntimeError if the worker died without an answer.
        """
        if self.items is not None:
            try:
                self.items.send((False, None))
                ok, value = self.out.recv()
            except (EOFError, BrokenPipeError):
                raise RuntimeError("the worker process ended without a result") from None
            finally:
                self.close()
            if not ok:
                raise value
            self.state = value
        return self.state

    def close(self):
        """End the worker process (steps still running are stopped)."""
        for conn in (self.items, self.out):
            if conn is not None:
                conn.close()
        self.items = self.out = None
        self.process = _stopped(self.process)


def _started(context, target, args, ours, theirs):
    """``target(*args)`` in a daemonic process forked by ``context``, started; or None where no
    process can start (:data:`NO_POOL`), with the pipe ends ``ours`` closed.  The ends
    ``theirs``, passed to the child in ``args``, are closed here either way."""
    try:
        process = context.Process(target=target, args=args, daemon=True)
        process.start()
    except NO_POOL:
        process = None
        for end in ours:
            end.close()
    for end in theirs:
        end.close()
    return process


def _stopped(process):
    """None, once ``process`` (or None) is ended: stopped if it still runs, then joined."""
    if process is not None:
        if process.is_alive():
            process.terminate()
        process.join()
    return None


def _chain_steps(items, out, step, state):
    """:class:`Chain`'s worker: fold ``step`` over the items received until the end mark, then
    send ``(True, state)`` or ``(False, exception)``.  After a failed step the items are still
    read to the end, so that the sender never blocks on a full pipe."""
    error = None
    while True:
        more, item = items.recv()
        if not more:
            break
        if error is None:
            try:
                state = step(state, item)
            except Exception as caught:  # re-raised by Chain.result
                error = caught
    out.send((False, error) if error is not None else (True, state))
    out.close()


def _send_result(conn, job):
    """Run ``job`` and send ``(True, result)``, or ``(False, exception)``, through ``conn``."""
    try:
        out = (True, _run(job))
    except Exception as error:  # re-raised by Background.result
        out = (False, error)
    conn.send(out)
    conn.close()


def checked_workers(workers):
    """``workers`` as an int; ValueError unless it is an integer >= 1."""
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise ValueError(f"workers must be an integer >= 1, got {workers!r}")
    return int(workers)


def _run(job):
    return job[0](*job[1:])


def _picklable(jobs):
    """Whether every job can be sent to a worker (a lambda or a local function cannot)."""
    try:
        pickle.dumps(jobs)
    except (pickle.PicklingError, TypeError, AttributeError):
        return False
    return True


def _fork_context():
    """The ``fork`` start method on Linux; None elsewhere (the jobs run in this process).

    A forked child needs nothing re-imported: ``spawn`` and ``forkserver`` run the caller's
    main module again in each child, which a script without an ``if __name__ ==
    "__main__":`` guard would execute a second time, side effects included.  Fork is not
    safe on macOS with its system frameworks, and Windows has none.
    """
    if sys.platform.startswith("linux") and "fork" in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("fork")
    return None
