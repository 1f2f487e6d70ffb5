#!/usr/bin/env python3
"""Two programs as processes, alternately (A B, B A, ...), in one directory: the median wall
(perf_counter around spawn and wait4) and user + sys CPU (wait4's rusage) of each. Paired runs
share the machine's load, so their difference is meaningful where a single wall figure is not.

  benchmarks/pair_runs.py REPS DIR "PROGRAM_A ARGS..." "PROGRAM_B ARGS..."
  e.g. benchmarks/pair_runs.py 31 /tmp/race/b3 "old/buckle run scene.json --out out --quiet" \\
       "build/bin/buckle run scene.json --out out --quiet"
"""
import os
import statistics
import subprocess
import sys
import time


def main():
    reps, d = int(sys.argv[1]), sys.argv[2]
    cmds = [sys.argv[3].split(), sys.argv[4].split()]
    wall, cpu = [[], []], [[], []]
    for i in range(reps):
        for k in ([0, 1] if i % 2 == 0 else [1, 0]):
            t0 = time.perf_counter()
            p = subprocess.Popen(cmds[k], cwd=d, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            _, _, ru = os.wait4(p.pid, 0)
            p.returncode = 0  # reaped by wait4
            wall[k].append(time.perf_counter() - t0)
            cpu[k].append(ru.ru_utime + ru.ru_stime)
    for k in (0, 1):
        print(f"{' '.join(cmds[k])}: wall median {statistics.median(wall[k]) * 1e3:.2f} ms, "
              f"CPU median {statistics.median(cpu[k]) * 1e3:.2f} ms ({reps} runs)")


if __name__ == "__main__":
    main()
