"""A `limn serve` on a free loopback port for the bench scripts (run as python3 bench/NAME.py,
which puts this folder on the import path)."""
import subprocess
import sys


def start_server(limn, workers=1):
    """Starts `limn serve` with `workers` render workers; returns (process, base URL)."""
    proc = subprocess.Popen([limn, "serve", "--listen", "127.0.0.1:0", "--workers", str(workers)],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    line = proc.stdout.readline()
    if "listening on" not in line:
        sys.exit("limn did not start: " + line)
    return proc, line.split("listening on")[1].strip()
