"""CPU seconds (user + system, from /proc/<pid>/stat) that named processes use between the
marks of a run, for the batch benchmark's account of where a run's CPU goes.

A process is named with a function returning its PID (or None while it has none), read
again at every mark, so a process started during the run (a new zygote) counts from 0.
With `children=True` the CPU of the process's children that it has reaped counts too
(a zygote's forked controllers once they have exited). A process that is gone at a mark
counts what it used up to its last mark.
"""
from .processes import cpu_seconds


class CpuMeter:
    def __init__(self, processes):
        """processes: {name: (pid function, children)}."""
        self.processes = processes
        self.stages = {}                  # stage -> {name: CPU s}
        self._last = {}                   # name -> (pid, CPU s at the last mark)
        self._sample()

    def _sample(self):
        used = {}
        for name, (pid_of, children) in self.processes.items():
            pid = pid_of()
            if pid is None:
                continue
            now = cpu_seconds(pid, children)
            if now is None:
                continue
            last_pid, last = self._last.get(name, (None, 0.0))
            used[name] = now - (last if last_pid == pid else 0.0)
            self._last[name] = (pid, now)
        return used

    def mark(self, stage):
        """The CPU each process used since the previous mark, as stage `stage`."""
        self.stages[stage] = {n: round(v, 3) for n, v in self._sample().items()}

    def totals(self):
        """{name: CPU s} over every stage so far."""
        total = {}
        for used in self.stages.values():
            for name, value in used.items():
                total[name] = round(total.get(name, 0.0) + value, 3)
        return total
