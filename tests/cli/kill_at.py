#!/usr/bin/env python3
"""Runs a command and kills it with SIGKILL from outside when a file event happens in DIR.

  kill_at.py DIR MODE K R -- COMMAND...

MODE files:    SIGKILL once the K-th checkpoint_*.h5 has appeared and then R more
               results_*.h5 (or the next checkpoint, whichever comes first).
MODE ckpt-tmp: SIGSTOP as soon as the K-th temporary of a checkpoint (.checkpoint_*.tmp.*)
               exists, then SIGKILL: the process dies while that checkpoint is being written.
Exit: 0 killed (prints what it saw), 3 the command ended before the event (prints its status),
4 ckpt-tmp saw the temporary but it was gone (renamed) when the process was stopped: no kill.
The directory is polled in a tight loop (os.scandir), so events are seen within microseconds.
"""
import os
import signal
import subprocess
import sys


def main():
    d, mode, k, r = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    cmd = sys.argv[sys.argv.index("--") + 1:]
    os.makedirs(d, exist_ok=True)
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    ckpts, results, tmps = set(), set(), set()
    results_at_k = None
    while True:
        try:
            names = [e.name for e in os.scandir(d)]
        except FileNotFoundError:
            names = []
        for n in names:
            if n.startswith("checkpoint_") and n.endswith(".h5"):
                ckpts.add(n)
            elif n.startswith("results_") and n.endswith(".h5"):
                results.add(n)
            elif n.startswith(".checkpoint_") and ".tmp." in n:
                tmps.add(n)
        if mode == "files" and len(ckpts) >= k:
            if results_at_k is None:
                results_at_k = len(results)
            if len(results) - results_at_k >= r or len(ckpts) > k:
                p.send_signal(signal.SIGKILL)
                p.wait()
                if p.returncode != -signal.SIGKILL:
                    print(f"the command ended (status {p.returncode}) before the kill: K={k}, R={r}")
                    return 3
                later = " and the next checkpoint" if len(ckpts) > k else ""
                print(f"killed (SIGKILL) once checkpoint #{k} then {len(results) - results_at_k} more results "
                      f"files{later} had appeared; newest checkpoint {max(ckpts)}")
                return 0
        if mode == "ckpt-tmp" and len(tmps) >= k:
            p.send_signal(signal.SIGSTOP)
            live = [n for n in os.listdir(d) if n.startswith(".checkpoint_") and ".tmp." in n]
            p.send_signal(signal.SIGKILL)
            p.wait()
            if p.returncode != -signal.SIGKILL:
                print(f"the command ended (status {p.returncode}) before the kill")
                return 3
            if not live:
                print(f"missed: checkpoint temporary #{k} was already renamed when stopped")
                return 4
            print(f"killed (SIGKILL) while writing a checkpoint: {live[0]} "
                  f"({os.path.getsize(os.path.join(d, live[0]))} bytes so far)")
            return 0
        if p.poll() is not None:
            print(f"the command ended (status {p.returncode}) before the event: mode {mode}, K={k}, R={r}; "
                  f"checkpoints seen {sorted(ckpts)}")
            return 3


if __name__ == "__main__":
    sys.exit(main())
