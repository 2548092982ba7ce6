#!/usr/bin/env python3
"""Prints one markdown row per fuzz run logged by fuzz/run_all.sh (fuzz/logs/TARGET-TAG.*):
the wall time between the run's start and end stamps (cargo's up-to-date check included),
libFuzzer's executions (`stat::number_of_executed_units`) and how the run ended."""
import glob, os, re

here = os.path.dirname(os.path.abspath(__file__))
rows = []
for log in sorted(glob.glob(os.path.join(here, "logs", "*.log"))):
    name = os.path.basename(log)[:-4]
    start, end = (os.path.join(here, "logs", f"{name}.{s}") for s in ("start", "end"))
    if not (os.path.exists(start) and os.path.exists(end)):
        continue
    target, tag = name.rsplit("-", 1)
    text = open(log, errors="replace").read()
    seconds = int(open(end).read()) - int(open(start).read())
    execs = re.findall(r"stat::number_of_executed_units: (\d+)", text)
    if not execs:  # killed before its final stats: the last status line
        execs = re.findall(r"^#(\d+)", text, re.M)
    crash = re.search(r"Test unit written to (\S+)", text)
    panic = re.search(r"panicked at (?:\S*/registry/src/[^/]+/|\S*/wt-fuzz/)?(\S+):\n(.*)", text)
    oom = re.search(r"memory allocation of (\d+) bytes failed", text)
    if crash:
        what = oom and f"allocation of {oom.group(1)} bytes" or panic and f"panic: {panic.group(2)} ({panic.group(1)})" or "crash"
        outcome = f"{what}; {os.path.basename(crash.group(1))}"
    else:
        outcome = "no crash"
    rows.append((target, int(tag), seconds, int(execs[-1]) if execs else 0, outcome))
for target, tag, seconds, execs, outcome in sorted(rows):
    print(f"| {target} | {tag} | {seconds} s ({seconds / 3600:.3f} h) | {execs:,} | {outcome} |")
print()
totals = {}
for target, tag, seconds, execs, outcome in rows:
    t = totals.setdefault(target, [0, 0, 0, 0])
    t[0] += 1
    t[1] += seconds
    t[2] += execs
    t[3] += outcome != "no crash"
for target, (runs, seconds, execs, crashes) in sorted(totals.items()):
    print(f"| {target} | {runs} | {seconds} s ({seconds / 3600:.2f} h) | {execs:,} | {crashes} |")
s = sum(t[1] for t in totals.values())
e = sum(t[2] for t in totals.values())
c = sum(t[3] for t in totals.values())
print(f"| all | {sum(t[0] for t in totals.values())} | {s} s ({s / 3600:.2f} h) | {e:,} | {c} |")
