#!/usr/bin/env python3
"""Run a command and record its wall time and CPU time (user + system of the child).

Usage: timed.py OUT.json CWD COMMAND [ARGS...]   (stdout/stderr of the command pass through)
The machine may be shared: CPU time is the fairer measure of cost; wall time is what a user waits.
"""
import json
import resource
import subprocess
import sys
import time

out, cwd, cmd = sys.argv[1], sys.argv[2], sys.argv[3:]
t0 = time.time()
rc = subprocess.call(cmd, cwd=cwd)
wall = time.time() - t0
ru = resource.getrusage(resource.RUSAGE_CHILDREN)
json.dump({"wall": wall, "cpu": ru.ru_utime + ru.ru_stime, "command": cmd}, open(out, "w"))
sys.exit(rc)
