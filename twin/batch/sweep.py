"""``twin sweep``: many scenarios, on all local cores or a Ray cluster, resumable.

Scenarios are grouped by trajectory (so no run pads to a longer one) and cut
into chunks, about two per worker process or per CPU of the Ray cluster; each
chunk is one batched simulation (``twin.envs.runner.run_many``) in a worker process
or a Ray task, and its rows are committed to the store (``DIR/results.sqlite``)
in one transaction as it completes. Re-running the same sweep skips every
scenario stored ok and retries the failed ones; a store written by another
version of the code or parameters (:func:`code_version`) is refused. A chunk
that raises is re-run one scenario at a time so that only the failing scenario
is marked failed, with its reason; a scenario that raised a MuJoCo warning is
marked failed too. Every scenario's numbers depend only on the scenario (its
own noise generator, its own simulation), so results are bit-identical
whatever the backend, worker count or chunking.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import dataclasses
import hashlib
import importlib.metadata
import math
import multiprocessing
import os
import pathlib
import signal
import tomllib
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures.process import BrokenProcessPool

from twin.batch.grid import GridPoint
from twin.batch.stops import handlers_put_back, raise_if_stopped
from twin.batch.store import ResultStore
from twin.exceptions import TwinError
from twin.physics.trajectories import trajectory
from twin.sim import report

BACKENDS = ("local", "ray")
STORE_FORMAT = 2  # bump when a key or a column changes meaning
PYPROJECT = pathlib.Path(__file__).resolve().parents[2] / "pyproject.toml"  # only in a source tree


class ClusterUnreachable(TwinError):
    """Ray could not connect to the cluster it was pointed at."""


class ClusterNotStarted(ClusterUnreachable):
    """Ray could not start or find its cluster: no scenario ran."""


class WorkerLost(TwinError):
    """A worker process died mid-sweep (killed, or out of memory)."""


def package_version() -> str:
    """The installed package's version, or the source tree's pyproject.toml's ("unknown" without either)."""
    try:
        return importlib.metadata.version("hydraulic-joint-twin")
    except importlib.metadata.PackageNotFoundError:  # run from a source tree
        if not PYPROJECT.exists():
            return "unknown"
        return tomllib.loads(PYPROJECT.read_text())["project"]["version"]


def code_version(plants: Mapping | None = None) -> str:
    """What a stored row depends on besides its scenario: the package, MuJoCo, NumPy and numba
    versions, and a hash of every plant preset's parameters, the four trajectories and the MJCF.
    ``plants``: the presets to hash in place of the registry's (``twin calibrate`` names the preset its
    fit makes, not the one installed before it)."""
    import mujoco
    import numba
    import numpy as np

    from twin.physics.model import MODEL_PATH
    from twin.physics.params import NOMINAL_PARAMS
    from twin.plants import PLANTS

    trajectories = [trajectory(n, spur_radius=NOMINAL_PARAMS.gears.spur_radius) for n in (1, 2, 3, 4)]
    presets = PLANTS if plants is None else plants
    params = hashlib.sha256(repr((presets, trajectories)).encode() + MODEL_PATH.read_bytes()).hexdigest()[:16]
    return (f"store {STORE_FORMAT}, twin {package_version()}, mujoco {mujoco.__version__}, "
            f"numpy {np.__version__}, numba {numba.__version__}, params {params}")


def open_store(out: pathlib.Path) -> ResultStore:
    """``out/results.sqlite``; raises StaleStore if another version of the code or parameters wrote it."""
    return ResultStore(out / "results.sqlite", version=code_version())


def result_record(point: GridPoint, result) -> dict:
    record = report.summary(result)
    record.update(
        key=point.key, supply_kpa=point.supply_kpa, pwm_period_ms=point.pwm_period_ms,
        peak_spur_tooth_n=float(result.trace.tooth_force_spur.max()),
        peak_rack_tooth_n=float(max(result.trace.tooth_force_rack_a.max(), result.trace.tooth_force_rack_b.max())),
        status="failed" if result.warnings else "ok",
        reason="; ".join(result.warnings),
    )
    return record


def failed_record(point: GridPoint, error: BaseException) -> dict:
    nan = math.nan
    return dict(key=point.key, controller=point.controller, trajectory=point.trajectory, payload_g=point.payload_g,
                orientation=point.orientation, plant=point.plant, seed=point.seed, supply_kpa=point.supply_kpa,
                pwm_period_ms=point.pwm_period_ms, noise=True, rmse_deg=nan, sse_deg=nan, max_error_deg=nan,
                duration_s=nan, peak_spur_tooth_n=nan, peak_rack_tooth_n=nan, status="failed",
                reason=f"{type(error).__name__}: {error}", warnings=[])


def run_chunk(points: Sequence[GridPoint]) -> list[dict]:
    """Simulate ``points`` as one batch on one thread; never raises (failures become rows)."""
    from twin.envs.runner import run_many

    try:
        results = run_many([p.scenario() for p in points], nthread=1)
        return [result_record(p, r) for p, r in zip(points, results, strict=True)]
    except Exception as error:  # noqa: BLE001 - recorded per scenario, never lost
        if len(points) == 1:
            return [failed_record(points[0], error)]
        return [row for p in points for row in run_chunk([p])]


MAX_CHUNK = 64  # scenarios per batch: bounds what an interrupt or a crash can lose (one batch per worker);
# 2026-11-24, 880 as-built runs on 2 workers: 64 as fast as 128 (17.5-19.6 s against 20.2-21.1 s), 32 35 % slower


def make_chunks(points: Sequence[GridPoint], workers: int) -> list[list[GridPoint]]:
    """Chunks of one trajectory each, about two per worker in all: every tick of a
    batch costs ~0.4 ms of Python whatever its size, so few large batches are fastest."""
    by_trajectory: dict[int, list[GridPoint]] = {}
    for p in points:
        by_trajectory.setdefault(p.trajectory, []).append(p)
    size = max(4, min(MAX_CHUNK, math.ceil(len(points) / (2 * workers))))
    chunks = []
    for group in by_trajectory.values():
        pieces = math.ceil(len(group) / size)
        step = math.ceil(len(group) / pieces)
        chunks += [group[i:i + step] for i in range(0, len(group), step)]
    return sorted(chunks, key=lambda c: -len(c) * trajectory(c[0].trajectory, spur_radius=1.0).duration)


@dataclasses.dataclass(frozen=True)
class SweepOutcome:
    records: list[dict]  # every scenario of the grid, in grid order
    skipped: int  # already in the store before this run
    ran: int


def _local(points: Sequence[GridPoint], workers: int, on_done: Callable[[list[dict]], None]) -> None:
    chunks = make_chunks(points, workers)
    if workers == 1:
        for chunk in chunks:
            on_done(run_chunk(chunk))
        return
    run_forked([(run_chunk, (chunk,)) for chunk in chunks], workers, on_done)


def run_forked(calls: Sequence[tuple[Callable, tuple]], workers: int, on_done: Callable) -> None:
    """Each ``function(*arguments)`` of ``calls`` (module-level functions) on ``workers`` forked processes
    (no more than there are calls), ``on_done(result)`` in the parent as each finishes. The kernels are compiled once before the fork;
    on Ctrl-C, SIGTERM or an error the queued calls are cancelled and the workers killed, not waited for."""
    import twin.envs.runner  # noqa: F401 - imported and compiled once here, inherited by every forked worker
    from twin.sim.plant_state import compile_kernels

    compile_kernels()
    pool = fork_pool(max(1, min(workers, len(calls))))
    try:
        futures = [pool.submit(function, *arguments) for function, arguments in calls]
        for future in concurrent.futures.as_completed(futures):
            on_done(future.result())
            raise_if_stopped()  # a stop Python swallowed: what finished is handed on, the rest stopped
    except BaseException:
        # Ctrl-C, SIGTERM or an error: what finished has been handed to on_done; the calls in flight are
        # lost (at most one per worker), and the workers are stopped now rather than waited for.
        kill_pool(pool)
        raise
    else:
        pool.shutdown(wait=True)


def fork_pool(workers: int) -> concurrent.futures.ProcessPoolExecutor:
    """A pool of ``workers`` forked processes, each set up by :func:`worker_setup`."""
    return concurrent.futures.ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("fork"),
                                                  initializer=worker_setup)


MANAGER_JOIN_S = 5.0  # s: how long a killed pool's manager thread may take to see its workers gone (it takes ms)


def kill_pool(pool: concurrent.futures.ProcessPoolExecutor) -> None:
    """Stop ``pool`` now: its queued calls cancelled, its workers killed rather than waited for. Then wait (a
    few seconds at most) for the pool's manager thread to see them gone and end: left running into the
    interpreter's exit, it could write to a wake-up pipe already closed, and a Ctrl-C printed a traceback after
    its one line (1 in 13 interrupted `twin validate` runs, found 2026-11-27)."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    manager = getattr(pool, "_executor_manager_thread", None)
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.kill()
    if manager is not None:
        manager.join(timeout=MANAGER_JOIN_S)


def worker_setup() -> None:
    """In a worker: Ctrl-C is the parent's to handle (it stops the workers itself), and SIGTERM (sent to the
    whole process group by a scheduler) ends a worker quietly instead of raising KeyboardInterrupt in it
    as the parent's handler would. A worker also dies
    with its parent (Linux's parent-death signal): a worker outliving a SIGKILLed sweep would hold the
    inherited lock on the output folder, and the resume would be refused."""
    parent = os.getppid()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # not the parent's Ctrl-C stand-in: a SIGTERM just ends a worker
    if signal.getsignal(signal.SIGHUP) is not signal.SIG_IGN:  # likewise when the terminal closes (unless
        signal.signal(signal.SIGHUP, signal.SIG_DFL)  # ``nohup``: then the parent ignores it, and so do they)
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # not Linux: the parent's own handlers still stop the workers
        return
    if os.getppid() != parent:  # the parent died before the signal was set
        os._exit(1)


def _ray(points: Sequence[GridPoint], workers: int | None, address: str | None,
         on_done: Callable[[list[dict]], None]) -> None:
    """Chunks as Ray tasks, sized for ``workers`` or else for every CPU of the cluster."""
    if not points:
        return  # no cluster to start
    import ray

    where = address or os.environ.get("RAY_ADDRESS") or None

    def cluster(call, *args, **kwargs):
        """A call to Ray; its ConnectionError (an OSError, which would read as a file that cannot be written)
        said as the cluster's. Only Ray's calls: a broken pipe in ``on_done`` is not the cluster's."""
        try:
            return call(*args, **kwargs)
        except ConnectionError as error:
            raise ClusterUnreachable(f"lost or could not reach the Ray cluster at {where or 'a local Ray'}: "
                                     f"{str(error).splitlines()[0]}; finished scenarios are kept, run the same "
                                     "command again to finish the rest") from None

    started_here = not ray.is_initialized()
    if started_here:  # log_to_driver=False: worker prints would flood the progress bar
        try:  # ray.init takes SIGTERM over: a kill then ended the sweep with exit 134 and a C++ stack dump
            with handlers_put_back():
                ray.init(address=where, include_dashboard=False, log_to_driver=False)
        except ConnectionError as error:  # ``auto`` with no cluster running: found only here
            raise ClusterNotStarted(f"could not reach the Ray cluster at {where or 'a local Ray'}: "
                                    f"{str(error).splitlines()[0]}; no scenario ran") from None
        except BaseException:  # a stop while Ray started (a kill that met Ray's own handler is handed back as one
            with contextlib.suppress(Exception):  # by handlers_put_back): what Ray had started goes with it
                ray.shutdown()
            raise
    pending = []
    try:
        cpus = workers or int(cluster(ray.cluster_resources).get("CPU", 1))
        remote = ray.remote(run_chunk)
        pending = [cluster(remote.remote, chunk) for chunk in make_chunks(points, max(1, cpus))]
        while pending:
            done, pending = cluster(ray.wait, pending, num_returns=1)
            on_done(cluster(ray.get, done[0]))
    finally:  # best effort: a cluster already lost refuses these too, and must not hide why the sweep stopped
        with contextlib.suppress(ConnectionError):
            if started_here:  # the job ends here (a joined cluster's clean-up of a finished job ends its tasks): no
                ray.shutdown()  # cancel, which raced the tasks' replies (Ray then crashed a stopped sweep, 5 of 31)
            else:  # the caller's Ray lives on: these tasks would run on in it
                for ref in pending:
                    ray.cancel(ref)


def counting(bar) -> Callable[[int], None]:
    """A ``progress`` for :func:`run_sweep` that counts on ``bar`` (a tqdm bar) and redraws it at each count, so
    that a resumed sweep shows what was done before at once, not at the end of its first batch."""
    def count(n: int) -> None:
        bar.update(n)
        bar.refresh()

    return count


def run_sweep(points: Sequence[GridPoint], *, out: pathlib.Path, workers: int | None = None,
              backend: str = "local", address: str | None = None,
              progress: Callable[[int], None] | None = None) -> SweepOutcome:
    """Run every point not stored ok in ``out/results.sqlite``; return all rows in grid order.
    ``workers``: local processes (default: all cores); with Ray, the CPUs that chunks are sized for
    (default: the cluster's)."""
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}: choose one of {', '.join(BACKENDS)}")
    store = open_store(out)
    try:
        done = store.done()
        todo = [p for p in points if p.key not in done]
        if progress is not None and len(points) > len(todo):
            progress(len(points) - len(todo))  # a resumed sweep counts what was done before

        def on_done(rows: list[dict]) -> None:
            store.add(rows)
            if progress is not None:
                progress(len(rows))
            raise_if_stopped()  # a stop Python swallowed: this batch is stored, the rest stopped (every backend)

        try:
            if backend == "ray":
                _ray(todo, workers, address, on_done)
            else:
                _local(todo, workers or os.cpu_count() or 1, on_done)
        except BrokenProcessPool:
            raise WorkerLost(f"a worker process died (killed, or out of memory?); the finished scenarios are kept "
                             f"in {store.path}: run the same command again to finish the rest") from None
        return SweepOutcome(records=store.records([p.key for p in points]),
                            skipped=len(points) - len(todo), ran=len(todo))
    finally:
        store.close()
