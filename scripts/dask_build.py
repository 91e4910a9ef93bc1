#!/usr/bin/env python3
"""Runs a `terramp-data plan` on Dask distributed: one task per partition, the merge when all are
done.

    terramp-data plan --synth-size 8192 --partitions 64 --out plan.toml
    python scripts/dask_build.py --plan plan.toml --out DATASET --local 4
    python scripts/dask_build.py --plan plan.toml --out DATASET --scheduler tcp://host:8786

Each task runs `terramp-data build --plan PLAN --partition I` in a subprocess on a worker (the
binary and the plan at the same paths on every node, the plan's parts folder on a file system they
all share). A failed task is retried (`--retries`); a task whose worker dies is rescheduled by Dask
itself. A job skips a partition already built for the plan, so running this again after a failure,
a kill or a lost cluster resumes the build: only unfinished partitions are built. The merge (which
also reduces the levels above the partitions' subtrees) runs as the last task.
"""

import argparse
import os
import subprocess
import sys
import time
import tomllib


def run(command):
    """Runs a terramp-data command; its last output line, or an error with its stderr."""
    proc = subprocess.run(command, capture_output=True, text=True)
    if proc.returncode != 0:
        detail = (proc.stderr or proc.stdout).strip()[-2000:]
        raise RuntimeError(f"{' '.join(command)}: exit {proc.returncode}: {detail}")
    lines = proc.stdout.strip().splitlines()
    return lines[-1] if lines else ""


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--plan", required=True, help="the plan file (terramp-data plan)")
    parser.add_argument("--out", required=True, help="the dataset folder the merge writes")
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--scheduler", help="address of a running Dask scheduler, tcp://host:port")
    where.add_argument("--local", type=int, metavar="N", help="start a LocalCluster of N single-threaded workers")
    parser.add_argument("--terramp-data", default="terramp-data", help="the builder binary, same path on every worker")
    parser.add_argument("--retries", type=int, default=2, help="retries of a failed partition (default 2)")
    args = parser.parse_args()

    plan_path = os.path.abspath(args.plan)
    with open(plan_path, "rb") as f:
        plan = tomllib.load(f)
    partitions, plan_hash = plan["partitions"], plan["hash"]
    binary = os.path.abspath(args.terramp_data) if os.sep in args.terramp_data else args.terramp_data
    out = os.path.abspath(args.out)

    from dask.distributed import Client, LocalCluster, as_completed

    if args.local:
        cluster = LocalCluster(n_workers=args.local, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
    else:
        cluster, client = None, Client(args.scheduler)
    workers = len(client.scheduler_info()["workers"])
    print(f"dask: {partitions} partitions of plan {plan_hash} on {workers} workers", flush=True)

    start = time.monotonic()
    futures = [
        client.submit(
            run,
            [binary, "build", "--plan", plan_path, "--partition", str(part)],
            key=f"terramp-partition-{plan_hash}-{part}",
            retries=args.retries,
            pure=False,
        )
        for part in range(partitions)
    ]
    done, failed = 0, []
    for future in as_completed(futures):
        try:
            line = future.result()
        except Exception as error:  # the task's own error, after its retries
            failed.append(str(error))
            print(f"dask: FAILED {error}", flush=True)
            continue
        done += 1
        elapsed = time.monotonic() - start
        eta = elapsed / done * (partitions - done)
        print(f"dask: [{done}/{partitions}] {line} (elapsed {elapsed:.0f} s, ETA {eta:.0f} s)", flush=True)
    if failed:
        print(f"dask: {len(failed)} partitions failed; run again to build only those", file=sys.stderr)
        sys.exit(1)

    merge = client.submit(run, [binary, "merge", "--plan", plan_path, "--out", out], key=f"terramp-merge-{plan_hash}", pure=False)
    print(f"dask: {merge.result()}", flush=True)
    print(f"dask: done in {time.monotonic() - start:.1f} s", flush=True)
    client.close()
    if cluster is not None:
        cluster.close()


if __name__ == "__main__":
    main()
