"""Studies: independent work units run through any concurrent.futures.Executor, results back in task order.

A study (the report's comparison, the probe, your own sweep) is many runs that do not depend on each other. Each
unit is a top-level function called with plain data (keyword arguments) that returns plain data or numpy arrays,
so that it can be pickled to another process or machine. ODE is deterministic within a process (every scene sets
its own ODE random seed), so a unit gives the same numbers bit for bit wherever it runs; only wall-clock timings
differ.

Executors by name (``make_executor``):

- ``local``: a process pool over every core this process may use (the default of ``steadystep compare`` and
  ``probe``). Its workers start cheaply: they are forked from a server process that imported steadystep's study
  modules once (multiprocessing's forkserver, WORKER_PRELOAD), instead of each importing them anew, and they hold
  none of this process's threads or ODE state;
- ``serial`` (or ``none``): in this process, one unit after the other (debugging, the one-process measurement);
- ``dask``: a Dask distributed cluster on this machine, one single-threaded worker process per core, shut down
  after;
- ``dask:ADDRESS``: an existing Dask scheduler (``tcp://host:8786``); its workers need steadystep installed.

Dask is optional (``pip install 'steadystep[dask]'``) and imported only when asked for. The local pool starts fresh
interpreters (spawn, as Dask's workers): a script that uses it must keep its top level under
``if __name__ == "__main__":``, as with any process pool.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import itertools
import os
from collections.abc import Callable, Iterable, Iterator, Mapping

# How long to wait for an existing Dask scheduler before calling it unreachable, and then for it to have a worker (s).
DASK_CONNECT_TIMEOUT_S = 10
DASK_WORKER_TIMEOUT_S = 10
DASK_EXTRA_HINT = "pip install 'steadystep[dask]'"
EXECUTOR_NAMES = ("local", "serial", "none", "dask", "dask:ADDRESS")
# What the local pool's fork server imports once for all its workers: the units of the report's task graph.
WORKER_PRELOAD = ["steadystep.report.tasks", "steadystep.report.figures"]


class ExecutorUnavailable(RuntimeError):
    """An executor that cannot be had: an unknown name, Dask not installed, a scheduler that cannot be reached. The
    message is one line naming the spec."""


class SerialExecutor(concurrent.futures.Executor):
    """Runs each unit in this process when it is submitted; ``sweep`` runs its units one by one through it."""

    def submit(self, fn, /, *args, **kwargs):
        future = concurrent.futures.Future()
        try:
            result = fn(*args, **kwargs)
        except BaseException as error:  # handed to whoever reads the future, as a pool would
            future.set_exception(error)
        else:
            future.set_result(result)
        return future


def _ignore_interrupt() -> None:
    """In a pool's worker: Ctrl-C, sent to the whole process group, is the caller's to handle (it stops the workers
    and says so in one line); a worker would only print a traceback."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


@contextlib.contextmanager
def _workers_ignore_interrupt():
    """Processes started within ignore Ctrl-C (an ignored signal stays ignored in a child, across exec), so that
    Dask's workers leave it to this process, which closes the cluster and says so in one line, instead of each
    printing a traceback. A Ctrl-C during the cluster's start-up (a few seconds) is lost."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield  # only the main thread may change signal handlers, and only it receives Ctrl-C
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    if previous is None:  # a handler set outside Python: put the default back
        previous = signal.default_int_handler
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _stop_workers(pool: concurrent.futures.ProcessPoolExecutor) -> None:
    """Terminates a process pool's workers now. The pool has no public way before Python 3.14
    (terminate_workers), hence its _processes."""
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        process.terminate()


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


@contextlib.contextmanager
def make_executor(spec: str = "local", workers: int | None = None) -> Iterator[concurrent.futures.Executor]:
    """The executor that spec names (see the module's docstring), shut down (and a local Dask cluster closed) when
    the with-block ends. workers: the local pool's processes (default one per usable core). Raises ExecutorUnavailable, one line naming the spec, for an unknown spec, Dask missing, a
    scheduler that does not answer as one within DASK_CONNECT_TIMEOUT_S (10 s), or one without a worker within
    DASK_WORKER_TIMEOUT_S (10 s)."""
    if not isinstance(spec, str):
        raise ExecutorUnavailable(f"executor = {spec!r}: must be one of {', '.join(EXECUTOR_NAMES)}")
    if spec in ("serial", "none"):
        yield SerialExecutor()
    elif spec == "local":
        pool = concurrent.futures.ProcessPoolExecutor(workers or usable_cores(), _worker_context(),
                                                      initializer=_ignore_interrupt)
        try:
            yield pool
        except BaseException:
            _stop_workers(pool)  # Ctrl-C or a failure: the units still running are not waited for
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
    elif spec == "dask" or spec.startswith("dask:"):
        with _dask_executor(spec) as executor:
            yield executor
    else:
        raise ExecutorUnavailable(f"executor = {spec!r}: unknown; use one of {', '.join(EXECUTOR_NAMES)}")


def _worker_context():
    """forkserver where the platform has it (workers forked from a server that preloaded WORKER_PRELOAD: no import
    per worker, nothing of this process's state), else spawn (fresh interpreters that import steadystep
    themselves)."""
    import multiprocessing
    import multiprocessing.forkserver

    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(WORKER_PRELOAD)
    # Started now, not at the first unit: its imports (0.6 s, matplotlib) go on while this process prepares the
    # units, instead of holding up the first of them.
    multiprocessing.forkserver.ensure_running()
    return context


def capacity(executor: concurrent.futures.Executor) -> int:
    """How many units executor runs at once: a process pool's workers, a Dask cluster's threads, else the usable
    cores."""
    workers = getattr(executor, "_max_workers", None)
    if isinstance(workers, int) and workers > 0:
        return workers
    client = getattr(executor, "_client", None)
    if client is not None:
        try:
            return max(1, sum(client.nthreads().values()))
        except Exception:  # noqa: BLE001 - a cluster that cannot say: fall back to this machine's cores
            pass
    return usable_cores()


def submit(executor: concurrent.futures.Executor, function: Callable, task: Mapping) -> concurrent.futures.Future:
    """executor.submit(function, **task), the task's names going to function alone (never to an executor's own
    submit keywords: Dask's key, priority, workers...)."""
    return executor.submit(_apply, function, dict(task))


@contextlib.contextmanager
def _dask_executor(spec: str) -> Iterator[concurrent.futures.Executor]:
    try:
        import distributed
    except ImportError:
        raise ExecutorUnavailable(f"executor = {spec!r}: Dask distributed is not installed: {DASK_EXTRA_HINT}") \
            from None
    address = spec[len("dask:"):] if spec.startswith("dask:") else None
    if address == "":
        raise ExecutorUnavailable(f"executor = {spec!r}: no scheduler address after 'dask:' (dask:tcp://HOST:PORT)")
    with contextlib.ExitStack() as stack:
        if address is None:
            import logging

            # One single-threaded worker process per core: ODE's random seed is global to a process, so two scenes
            # must never step in one process at once.
            with _workers_ignore_interrupt():
                cluster = stack.enter_context(distributed.LocalCluster(
                    n_workers=usable_cores(), threads_per_worker=1, processes=True, dashboard_address=None,
                    silence_logs=logging.ERROR))
            client = stack.enter_context(distributed.Client(cluster))
        else:
            client = stack.enter_context(_connect(distributed, spec, address))
            try:
                client.wait_for_workers(1, timeout=DASK_WORKER_TIMEOUT_S)
            except Exception:  # TimeoutError, or the scheduler went away
                raise ExecutorUnavailable(f"executor = {spec!r}: the Dask scheduler at {address} has no workers "
                                          f"(waited {DASK_WORKER_TIMEOUT_S} s): start some (dask worker "
                                          f"{address}) or use --executor local") from None
        executor = client.get_executor()
        try:
            yield executor
        finally:
            executor.shutdown(wait=False)


def _connect(distributed, spec: str, address: str):
    """A Client of the scheduler at address, or ExecutorUnavailable within DASK_CONNECT_TIMEOUT_S. Dask bounds the
    TCP connection but not its handshake (a peer that accepts and says nothing is waited for for ever), and fails
    with whatever the transport raises (ucx:// not installed, tls:// without certificates, a peer speaking another
    protocol: TypeError, MemoryError ...): the connection is made in a thread that is given up on after the
    timeout, and every failure becomes the one-line refusal."""
    import threading

    outcome: dict = {}

    def connect() -> None:
        try:
            outcome["client"] = distributed.Client(address, timeout=DASK_CONNECT_TIMEOUT_S)
        except BaseException as error:  # noqa: BLE001 - handed to the caller below as the refusal's reason
            outcome["error"] = error

    connecting = threading.Thread(target=connect, name="steadystep-dask-connect", daemon=True)
    connecting.start()
    connecting.join(DASK_CONNECT_TIMEOUT_S + 1)
    if "client" in outcome:
        return outcome["client"]
    error = outcome.get("error")
    if error is None:
        reason = f"no answer within {DASK_CONNECT_TIMEOUT_S} s (is it a Dask scheduler?)"
    else:  # Dask's own timeout says how long it waited
        reason = f"{type(error).__name__}: {' '.join(str(error).split())[:200]}"
    raise ExecutorUnavailable(f"executor = {spec!r}: cannot reach the Dask scheduler at {address}: {reason}")


def grid(**axes: Iterable) -> list[dict]:
    """Every combination of the axes' values as keyword dicts, the last axis varying fastest:
    grid(k=[1, 2], c=[0.5]) == [{"k": 1, "c": 0.5}, {"k": 2, "c": 0.5}]. No axes: one empty dict."""
    names, values = list(axes), [list(v) for v in axes.values()]
    return [dict(zip(names, combination)) for combination in itertools.product(*values)]


def sweep(function: Callable, tasks: Iterable[Mapping], executor: concurrent.futures.Executor | str | None = None,
          progress: bool | None = None, desc: str = "steadystep sweep", unit: str = "run",
          label: Callable[[Mapping], str] | None = None) -> list:
    """function(**task) for every task (a dict of keyword arguments, e.g. from grid), through executor; returns
    the results in the tasks' order, whatever order they complete in.

    function must be a top-level function, and tasks and results plain data, when the executor is another process
    (they are pickled). executor: any concurrent.futures.Executor; a name for make_executor ("local", "dask", ...),
    made and shut down for this call; None: in this process. progress: a tqdm bar on stderr (None: only on a
    terminal; needs tqdm), updated as units complete, with label(task) of the last one. The first unit to fail
    cancels those not started and its exception is raised."""
    tasks = [dict(task) for task in tasks]
    results = [None] * len(tasks)
    for index, result in as_completed(function, tasks, executor, progress, desc, unit, label):
        results[index] = result
    return results


def as_completed(function: Callable, tasks: Iterable[Mapping],
                 executor: concurrent.futures.Executor | str | None = None, progress: bool | None = None,
                 desc: str = "steadystep sweep", unit: str = "run",
                 label: Callable[[Mapping], str] | None = None) -> Iterator[tuple[int, object]]:
    """As sweep, but yields (the task's index, its result) as each unit completes (in this process: in the tasks'
    order), so that the caller can use a result while the others still run. Leaving the loop early cancels the units
    not started."""
    tasks = [dict(task) for task in tasks]
    if isinstance(executor, str):
        with make_executor(executor) as made:
            yield from as_completed(function, tasks, made, progress, desc, unit, label)
        return
    with progress_bar(len(tasks), progress, desc, unit) as bar:
        def done(task):
            if label is not None:
                bar.set_postfix_str(label(task), refresh=False)
            bar.update()

        if executor is None or isinstance(executor, SerialExecutor):
            for index, task in enumerate(tasks):
                result = function(**task)
                done(task)
                yield index, result
            return
        futures = [submit(executor, function, task) for task in tasks]
        indices = {future: i for i, future in enumerate(futures)}
        try:
            for future in concurrent.futures.as_completed(futures):
                result = future.result()  # raises the unit's exception at once
                done(tasks[indices[future]])
                yield indices[future], result
        finally:  # a failure, or a caller that stopped early: nothing more is started
            for future in futures:
                future.cancel()


def _apply(function: Callable, task: dict):
    """function(**task): the task's names go to function alone, never to an executor's own submit keywords (Dask's
    key, priority, workers...)."""
    return function(**task)


class _NoBar:
    def update(self, n: int = 1) -> None:
        pass

    def set_postfix_str(self, text: str = "", refresh: bool = True) -> None:
        pass

    def set_description_str(self, text: str = "", refresh: bool = True) -> None:
        pass


@contextlib.contextmanager
def progress_bar(total: int, progress: bool | None, desc: str, unit: str = "run"):
    """A tqdm bar of total units on stderr, closed at the end (progress None: only on a terminal; False, or None
    without tqdm installed: a bar that shows nothing)."""
    try:
        from tqdm import tqdm
    except ImportError:
        if progress:
            raise
        tqdm = None  # the core package does not need tqdm: no bar unless one is asked for
    if progress is False or tqdm is None:
        yield _NoBar()
        return

    bar = tqdm(total=total, desc=desc, unit=unit, disable=None if progress is None else not progress)
    try:
        yield bar
    finally:
        bar.close()
