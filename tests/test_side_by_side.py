"""Independent jobs side by side: the results of the jobs run one after the other, in order,
from other processes where a pool can start and from this one where it cannot."""

import math
import multiprocessing
import os
import sys
import time

import numpy as np
import pytest

from igl_spheremap.uses.side_by_side import Background, Chain, side_by_side

linux = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="forks on Linux only")


def pid_and_square(x):
    return os.getpid(), x * x


def fails(x):
    raise ValueError(f"job {x} fails")


@pytest.mark.parametrize("workers", [1, 2, 3, 8])
def test_results_are_those_of_the_jobs_in_their_order(workers):
    jobs = [(math.factorial, 5), (np.linalg.norm, np.array([3.0, 4.0])), (math.comb, 6, 2),
            (sorted, [3, 1, 2])]
    assert side_by_side(jobs, workers) == [120, 5.0, 15, [1, 2, 3]]


@linux
def test_the_first_job_runs_here_and_the_others_in_worker_processes():
    out = side_by_side([(pid_and_square, x) for x in range(4)], 3)
    assert [sq for _, sq in out] == [0, 1, 4, 9]
    assert out[0][0] == os.getpid()
    others = {pid for pid, _ in out[1:]}
    assert os.getpid() not in others and 1 <= len(others) <= 2


def test_one_worker_runs_every_job_here():
    out = side_by_side([(pid_and_square, x) for x in range(3)], 1)
    assert {pid for pid, _ in out} == {os.getpid()}


@pytest.mark.parametrize("platform", ["darwin", "win32"])
def test_elsewhere_than_linux_every_job_runs_here(monkeypatch, platform):
    """Children are forked on Linux only (spawn would run an unguarded main script again)."""
    monkeypatch.setattr(sys, "platform", platform)
    out = side_by_side([(pid_and_square, x) for x in range(3)], 3)
    assert out == [(os.getpid(), 0), (os.getpid(), 1), (os.getpid(), 4)]


def test_jobs_that_cannot_be_pickled_run_here():
    offset = 10
    out = side_by_side([(lambda x: x + offset, 1), (lambda x: x + offset, 2)], 3)
    assert out == [11, 12]


def _in_a_daemon(task):
    """What ``task()`` returns, and the process id, from inside a daemonic process."""
    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue()
    worker = ctx.Process(target=lambda: queue.put((task(), os.getpid())), daemon=True)
    worker.start()
    out = queue.get(timeout=120)
    worker.join(timeout=60)
    return out


@linux
def test_inside_a_daemonic_process_the_jobs_run_in_it():
    """A ``multiprocessing`` (or Dask) worker is daemonic and may not start processes."""
    results, pid = _in_a_daemon(lambda: side_by_side([(pid_and_square, x) for x in range(3)], 3))
    assert [sq for _, sq in results] == [0, 1, 4]
    assert {p for p, _ in results} == {pid}


@pytest.mark.parametrize("workers", [1, 3])
def test_an_error_in_a_job_is_raised_here(workers):
    with pytest.raises(ValueError, match="job 2 fails"):
        side_by_side([(math.factorial, 3), (fails, 2)], workers)


@pytest.mark.parametrize("workers", [0, -1, 1.5, True, "2", None])
def test_workers_must_be_a_positive_integer(workers):
    with pytest.raises(ValueError, match="workers must be an integer >= 1"):
        side_by_side([(math.factorial, 3)], workers)


def slow_pid_and_square(x, seconds):
    time.sleep(seconds)
    return os.getpid(), x * x


@linux
def test_a_background_job_runs_in_a_worker_while_this_process_goes_on():
    """The job starts at once in another process; this one works meanwhile and then takes the
    result (waiting for it), the same each time it is asked for."""
    job = Background((slow_pid_and_square, 7, 0.5), 3)
    assert not job.done()
    here = side_by_side([(pid_and_square, 2)], 1)[0]
    pid, sq = job.result()
    assert sq == 49 and pid != os.getpid() and here == (os.getpid(), 4)
    assert job.done() and job.result() == (pid, 49)
    assert job.process is None  # the worker is gone once the result is in


@pytest.mark.parametrize("workers", [1, 3])
def test_a_background_job_that_cannot_start_a_worker_runs_here_when_asked(workers):
    offset = 10
    job = Background((lambda x: (os.getpid(), x + offset), 1), workers)  # does not pickle
    assert not job.done()
    assert job.result() == (os.getpid(), 11)
    job = Background((pid_and_square, 3), 1)
    assert job.result() == (os.getpid(), 9)


@pytest.mark.parametrize("workers", [1, 3])
def test_an_error_in_a_background_job_is_raised_when_its_result_is_asked_for(workers):
    job = Background((fails, 4), workers)
    with pytest.raises(ValueError, match="job 4 fails"):
        job.result()


@linux
def test_inside_a_daemonic_process_a_background_job_runs_in_it():
    """A ``multiprocessing`` (or Dask) worker may not start processes: the job runs there."""
    (pid, sq), daemon = _in_a_daemon(lambda: Background((pid_and_square, 5), 3).result())
    assert sq == 25 and pid == daemon != os.getpid()


def appended(state, item):
    """A chain step: the items so far, each with the process that took it."""
    return state + [(os.getpid(), item)]


def fails_on_three(state, item):
    if item == 3:
        raise ValueError("step 3 fails")
    return state + [item]


@linux
def test_a_chain_runs_its_steps_in_order_in_a_worker_while_this_process_goes_on():
    """Each item is stepped in the worker, in the order sent; the result is what the steps give
    one after the other here."""
    chain = Chain(appended, [], 3)
    for item in range(5):
        chain.send(item)
    steps = chain.result()
    assert [item for _, item in steps] == list(range(5))
    assert {pid for pid, _ in steps} == {steps[0][0]} and steps[0][0] != os.getpid()
    assert chain.process is None and chain.result() == steps


@pytest.mark.parametrize("workers", [1, 3])
def test_a_chain_without_a_worker_steps_each_item_here_when_it_is_sent(monkeypatch, workers):
    """With one worker, or where no process forks, each step runs here at once."""
    monkeypatch.setattr(sys, "platform", "darwin")
    chain = Chain(appended, [], workers)
    chain.send("a")
    assert chain.state == [(os.getpid(), "a")]
    chain.send("b")
    assert chain.result() == [(os.getpid(), "a"), (os.getpid(), "b")]


@pytest.mark.parametrize("workers", [1, 3])
def test_an_error_in_a_chain_step_is_raised_when_its_result_is_asked_for(workers):
    """Items sent after the failing step (more than a pipe holds) neither block nor hide it."""
    chain = Chain(fails_on_three, [], workers)
    big = np.zeros(100_000)
    for item in (1, 2):
        chain.send(item)
    if workers == 1:
        with pytest.raises(ValueError, match="step 3 fails"):
            chain.send(3)
        return
    chain.send(3)
    for _ in range(20):
        chain.send(big)
    with pytest.raises(ValueError, match="step 3 fails"):
        chain.result()


def sleeping_chain():
    """A chain whose worker is busy for a minute."""
    chain = Chain(lambda state, seconds: time.sleep(seconds), None, 3)
    chain.send(60.0)
    return chain


@linux
@pytest.mark.parametrize("busy", [lambda: Background((slow_pid_and_square, 1, 60.0), 3),
                                  sleeping_chain], ids=["background", "chain"])
def test_closing_stops_a_busy_worker(busy):
    job = busy()
    process = job.process
    assert process.is_alive()
    job.close()
    assert not process.is_alive()


@linux
def test_inside_a_daemonic_process_a_chain_runs_in_it():
    def run():
        chain = Chain(appended, [], 3)
        chain.send(1)
        return chain.result()
    [(pid, item)], daemon = _in_a_daemon(run)
    assert item == 1 and pid == daemon != os.getpid()
