"""Runs a batch of scenarios on Dask: an embedded LocalCluster (one single-threaded worker
process per core, on 127.0.0.1, no dashboard) or an existing cluster's scheduler address.

Each run is one Dask task, m2wr_tools.batch.rig.run_scenario, whose result is a plain record; the
records are written to <output>/results.json and results.csv as they arrive, so an
interrupted batch resumes where it stopped (runs already in the results are skipped). A
worker that dies has its runs rescheduled by Dask on the others (the scheduler's
allowed-failures, 3 by default). The progress bar (tqdm) shows runs done, failures, runs per
wall minute and the ETA. Ctrl-C (SIGINT) or SIGTERM: the runs still queued are cancelled,
the workers close (each stops its simulator, controller and master), and any process the
batch started that is still alive is killed by PID (found by the batch's tag in its
environment, M2WR_BATCH); no traceback.
"""
import logging
import os
import signal
import sys
import time
import uuid

from distributed.diagnostics.plugin import WorkerPlugin

from ..running import processes
from . import results
from ..running.processes import Interrupted, raise_on_signals
from .rig import BATCH_TAG, RunOptions, close_rig, options_dict, run_scenario


PROFILER_CALLBACKS = ("profile", "profile-cycle")
# The embedded cluster's periodic chores, slowed: each process's event-loop tick (a blocked
# loop check) runs every 20 ms by default, the system monitor (dashboard figures) every
# 0.5 s, the nannies' memory check every 0.1 s. Slowed, the idle driver (scheduler,
# nannies, client) and worker processes give their share of a core back to the runs.
QUIET_CLUSTER = {
    "distributed.worker.profile.enabled": False,          # see _RigTeardown
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
}


class _RigTeardown(WorkerPlugin):
    """Dask worker plugin: stops the worker's statistical profiler when it joins the batch
    (it samples the worker's threads every 10 ms and keeps an hour of profiles: ~0.26 MiB a
    run of memory growth and CPU taken from the simulator; runs need neither), and stops the
    worker's rig when the worker closes."""
    name = "m2wr-rig"

    def setup(self, worker):
        for name in PROFILER_CALLBACKS:
            callback = worker.periodic_callbacks.get(name)
            if callback is not None:
                callback.stop()

    def teardown(self, worker):
        close_rig()


def _client(scheduler, workers):
    """(client, cluster or None)."""
    import dask
    from distributed import Client, LocalCluster
    if scheduler:
        return Client(scheduler, timeout="30s"), None
    with dask.config.set(QUIET_CLUSTER):
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None,
                               silence_logs=logging.ERROR)
    return Client(cluster), cluster


def run_batch(scenarios, options: RunOptions, scheduler=None, workers=None, resume=True,
              progress=True, say=print, task=run_scenario, on_record=None):
    """Runs every scenario not yet in <options.output>/results.json; returns the records of
    the whole batch (earlier ones included), in run-id order. Raises Interrupted on Ctrl-C
    after cleaning up (the records so far are written). `task(scenario dict, options dict)`
    is the Dask task of one run (a tool built on this runner passes its own);
    `on_record(record, bar)`, if given, is called with each new record as it arrives."""
    from distributed import as_completed
    from tqdm import tqdm

    os.makedirs(options.output, exist_ok=True)
    done = results.load(options.output) if resume else {}
    wanted = {s.run_id: s for s in scenarios}
    records = {k: v for k, v in done.items() if k in wanted}
    todo = [s for s in scenarios if s.run_id not in records]
    # every worker puts the tag in its children's environment (rig.Rig), not in its own
    options.batch = options.batch or uuid.uuid4().hex
    batch_info = {"runs": len(scenarios), "options": options_dict(options),
                  "scheduler": scheduler or "LocalCluster(%s workers)" % workers}
    if records:
        say("resuming: %d of %d runs already in %s" % (len(records), len(scenarios),
                                                         os.path.join(options.output, "results.json")))
    if not todo:
        results.write(options.output, records.values(), batch_info)
        return sorted(records.values(), key=lambda r: r["run_id"])

    old_handlers = raise_on_signals()
    client = cluster = bar = None
    futures = []
    failures = 0
    try:
        workers = workers or os.cpu_count() or 1
        say("starting %s" % ("a client of %s" % scheduler if scheduler
                             else "a LocalCluster of %d workers on 127.0.0.1" % workers))
        client, cluster = _client(scheduler, workers)
        client.register_plugin(_RigTeardown(), name=_RigTeardown.name)
        opts = options_dict(options)
        futures = [client.submit(task, s.as_dict(), opts, key="run-%s" % s.run_id,
                                 pure=False) for s in todo]
        pending = set(futures)          # a finished run's result is released at once, so
                                        # that no worker holds every record of the batch
        bar = tqdm(total=len(todo), unit="run", disable=not progress, dynamic_ncols=True,
                   file=sys.stderr, smoothing=0.1)
        started = time.monotonic()
        completed = as_completed(futures)
        futures = pending
        for future in completed:
            pending.discard(future)
            try:
                record = future.result()
            except Exception as err:        # the task itself failed (e.g. workers lost)
                scenario = wanted[future.key[len("run-"):]]
                record = {"run_id": scenario.run_id, "scenario": scenario.as_dict(),
                          "world": scenario.world_label, "x": scenario.x, "y": scenario.y,
                          "yaw": scenario.yaw, "seed": scenario.seed,
                          "task": scenario.task.kind, "success": False,
                          "reason": "the run's task failed on the cluster: %s: %s"
                          % (type(err).__name__, err)}
            future.release()
            records[record["run_id"]] = record
            failures += 0 if record.get("success") else 1
            results.write(options.output, records.values(), batch_info)
            bar.update(1)
            minutes = (time.monotonic() - started) / 60.0
            bar.set_postfix_str("failed %d, %.1f runs/min" % (failures, bar.n / minutes
                                                             if minutes > 0 else 0.0))
            if on_record is not None:
                on_record(record, bar)
    except Interrupted:
        raise
    finally:
        signal.signal(signal.SIGINT, signal.SIG_IGN)   # the clean-up runs to its end
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        if bar is not None:
            bar.close()
        for future in futures:
            if not future.done():
                future.cancel()
        try:
            if client is not None:
                client.close(timeout=30)
            if cluster is not None:
                cluster.close(timeout=30)
        except Exception as err:
            say("closing the cluster: %s: %s" % (type(err).__name__, err))
        killed = processes.kill_tagged(BATCH_TAG, options.batch)
        if killed:
            say("%d processes of the batch outlived the cluster's close; stopped by PID"
                % len(killed.splitlines()))
        results.write(options.output, records.values(), batch_info)
        for signum, handler in old_handlers.items():
            signal.signal(signum, handler)
    return sorted(records.values(), key=lambda r: r["run_id"])
