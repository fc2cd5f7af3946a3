#!/usr/bin/env python3
"""Durable jobs end to end (issue 24), measured in one run on this build:

  1. one 1,000-row job (the cube from 500 random views x coarse and uniform:1 at 32 px: small
     images, so that the store's share shows) on one `limn serve` with 2 workers on SQLite,
     the same on PostgreSQL, and on three processes (1 worker each) sharing PostgreSQL; the
     same rows through `limn batch --server` (no store) as the baseline; the
     same rows through `limn batch --server` (no store) as the baseline;
  2. resume: a process on SQLite SIGKILLed at 30% of that job and started again on the same
     file: the restart until it answers, until its first new row, until the job is done.

PostgreSQL is a throwaway server (initdb + pg_ctl on a temporary folder, Unix socket only), as in
the tests. Prints Markdown tables (bench/load_results.md, "Jobs").

  bench/jobs_bench.py [--rows 1000] [--lease 5]
"""
import argparse
import json
import os
import pwd
import shutil
import signal
import subprocess
import tempfile
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LIMN = os.path.join(ROOT, "build", "bin", "limn")


def http(port, method, path, body=None):
    request = urllib.request.Request(f"http://127.0.0.1:{port}{path}", method=method,
                                     data=body.encode() if body else None)
    try:
        with urllib.request.urlopen(request, timeout=120) as answer:
            return answer.status, answer.read().decode()
    except urllib.error.HTTPError as error:
        return error.code, error.read().decode()


class Postgres:
    def __init__(self):
        self.dir = tempfile.mkdtemp(prefix="limn-pg-bench-")
        self.bin = sorted(f"/usr/lib/postgresql/{v}/bin" for v in os.listdir("/usr/lib/postgresql"))[-1]
        self.as_user = []
        if os.geteuid() == 0:
            user = pwd.getpwnam("postgres")
            os.chown(self.dir, user.pw_uid, user.pw_gid)
            self.as_user = ["runuser", "-u", "postgres", "--"]
        self.run("initdb", "-D", f"{self.dir}/data", "-A", "trust", "-U", "postgres", "--no-sync")
        self.run("pg_ctl", "-D", f"{self.dir}/data", "-l", f"{self.dir}/log", "-w", "-o",
                 f"-k {self.dir} -c listen_addresses='' -c max_connections=60", "start")
        self.databases = 0

    def run(self, tool, *args):
        subprocess.run(self.as_user + [f"{self.bin}/{tool}", *args], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def database(self):
        self.databases += 1
        name = f"bench{self.databases}"
        subprocess.run(self.as_user + [f"{self.bin}/createdb", "-h", self.dir, "-U", "postgres", name],
                       check=True)
        return f"postgresql:///{name}?host={self.dir}&user=postgres"

    def close(self):
        self.run("pg_ctl", "-D", f"{self.dir}/data", "-m", "immediate", "-w", "stop")
        shutil.rmtree(self.dir, ignore_errors=True)


class Server:
    def __init__(self, store, workers, lease, work):
        config = os.path.join(work, f"config-{workers}-{lease}.json")
        with open(config, "w") as f:
            json.dump({"port": 0, "workers": workers, "logLevel": "off", "jobLeaseSeconds": lease,
                       "limits": {"maxJobRows": 100000}}, f)
        self.started = time.monotonic()
        self.process = subprocess.Popen([LIMN, "serve", "--config", config, "--job-store", store],
                                        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        line = self.process.stdout.readline()
        self.port = int(line.rsplit(":", 1)[1])
        self.ready_s = time.monotonic() - self.started

    def stop(self, sig=signal.SIGTERM):
        self.process.send_signal(sig)
        self.process.wait(timeout=60)


def spec(rows):
    with open(os.path.join(ROOT, "examples", "cube.obj")) as f:
        obj = f.read()
    return json.dumps({"meshes": [{"name": "cube", "mesh": {"format": "obj", "data": obj}}],
                       "methods": ["coarse", "uniform:1"], "views": rows // 2, "size": 32})


def job(port, job_id):
    return json.loads(http(port, "GET", f"/v1/jobs/{job_id}")[1])


def run_job(servers, body):
    start = time.monotonic()
    status, answer = http(servers[0].port, "POST", "/v1/jobs", body)
    assert status == 202, answer
    job_id = json.loads(answer)["id"]
    while True:
        state = job(servers[-1].port, job_id)
        if state["state"] not in ("queued", "running"):
            break
        time.sleep(0.1)
    seconds = time.monotonic() - start
    replicas = {}
    for row in state["rows"]:
        replicas[row["replica"]] = replicas.get(row["replica"], 0) + 1
    return seconds, state, replicas


def batch_baseline(body, work):
    """The same rows without a store: `limn batch --server` sends the same /v1/compare bodies."""
    server = Server("sqlite::memory:", 2, 30, work)
    with open(os.path.join(work, "spec.json"), "w") as f:
        f.write(body)
    out = os.path.join(work, "batch-out")
    start = time.monotonic()
    subprocess.run([LIMN, "batch", os.path.join(work, "spec.json"), "--server",
                    f"http://127.0.0.1:{server.port}", "--out", out], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    seconds = time.monotonic() - start
    server.stop()
    return seconds


def throughput(rows, lease, work, postgres):
    body = spec(rows)
    baseline = batch_baseline(body, work)
    print(f"| setup | workers in all | job time (s) | rows/s | rows per replica |")
    print("|---|---:|---:|---:|---|")
    print(f"| no store: limn batch --server, 1 process | 2 | {baseline:.1f} | {rows / baseline:.0f} | |",
          flush=True)
    cases = [("1 process, SQLite", lambda: ["sqlite:" + os.path.join(work, "one.sqlite")], 2),
             ("1 process, PostgreSQL", lambda: [postgres.database()], 2),
             ("3 processes, one PostgreSQL", lambda: [postgres.database()] * 3, 1)]
    for name, stores, workers in cases:
        servers = [Server(s, workers, lease, work) for s in stores()]
        seconds, state, replicas = run_job(servers, body)
        assert state["state"] == "done" and len(state["rows"]) == rows, state["progress"]
        print(f"| {name} | {workers * len(servers)} | {seconds:.1f} | {rows / seconds:.0f} | "
              f"{' / '.join(str(n) for n in sorted(replicas.values(), reverse=True))} |", flush=True)
        for s in servers:
            s.stop()


def resume(rows, lease, work):
    store = "sqlite:" + os.path.join(work, "resume.sqlite")
    first = Server(store, 2, lease, work)
    status, answer = http(first.port, "POST", "/v1/jobs", spec(rows))
    job_id = json.loads(answer)["id"]
    while job(first.port, job_id)["progress"]["done"] < rows * 0.3:
        time.sleep(0.05)
    done_before = job(first.port, job_id)["progress"]["done"]
    first.stop(signal.SIGKILL)
    killed = time.monotonic()
    second = Server(store, 2, lease, work)
    answering = time.monotonic() - killed
    first_row = None
    while True:
        state = job(second.port, job_id)
        if first_row is None and state["progress"]["done"] > done_before:
            first_row = time.monotonic() - killed
        if state["state"] not in ("queued", "running"):
            break
        time.sleep(0.05)
    finished = time.monotonic() - killed
    keys = [row["key"] for row in state["rows"]]
    second.stop()
    print(f"| rows done when killed | restart answering (s) | first new row (s) | job done (s) | "
          f"rows | duplicates |")
    print("|---:|---:|---:|---:|---:|---:|")
    print(f"| {done_before} | {answering:.2f} | {first_row:.2f} | {finished:.1f} | {len(keys)} | "
          f"{len(keys) - len(set(keys))} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=1000)
    parser.add_argument("--lease", type=int, default=5, help="jobLeaseSeconds of the servers")
    args = parser.parse_args()
    work = tempfile.mkdtemp(prefix="limn-jobs-bench-")
    postgres = Postgres()
    try:
        print(f"### {args.rows}-row job (cube, 32 px, coarse + uniform:1), jobLeaseSeconds {args.lease}\n")
        throughput(args.rows, args.lease, work, postgres)
        print(f"\n### Resume after SIGKILL at 30% (SQLite, 2 workers, jobLeaseSeconds {args.lease})\n")
        resume(args.rows, args.lease, work)
    finally:
        postgres.close()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
