#!/usr/bin/env python3
"""Run a grasp-sim batch on Ray: the shards of the inputs as Ray tasks, merged and checked.

    python3 scripts/ray_batch.py --out results.jsonl [--address auto] INPUTS... [-- BATCH FLAGS]

Each task runs the release binary on one shard,

    grasp-sim batch --shard K/N --resume --out WORK/shard-K.jsonl --jobs C [BATCH FLAGS] INPUTS

asking Ray for C CPUs (--cpus-per-task) and retried up to --max-retries times when it fails
(a worker or node lost, the binary killed): `--resume` makes a retry continue where the shard
stopped instead of starting it again. The driver gathers the shard files (returned through
Ray's object store, so the nodes need no shared folder for the outputs), then

    grasp-sim batch --merge GATHERED --out results.jsonl [BATCH FLAGS] INPUTS

puts them together in input order and checks that every input is there exactly once, from
the inputs as they are now. Running the script again after it was killed continues the run.

Without --address it starts a local Ray instance (--num-cpus); with --address (`auto`, or
`ray://head:10001`) the same command runs on a cluster. On a cluster the inputs and the
binary must be at the same path on every node (a shared filesystem), and --work-dir should be
on one too if a retried task is to find the lines its first attempt wrote.

Exit status: the merge's (0, 1 an expectation not met, 2 an object with an error line or a
failed check).
"""

import argparse
import ctypes
import os
import signal
import subprocess
import sys
import time

PR_SET_PDEATHSIG = 1


def die_with_parent():
    """A function for the child to call before exec that makes it die when the Ray worker
    that started it dies, so a killed task leaves no batch behind (the batch's own workers
    die with it in turn); None off Linux. prctl is looked up here, before the fork."""
    if not sys.platform.startswith("linux"):
        return None
    prctl = ctypes.CDLL(None, use_errno=True).prctl
    return lambda: prctl(PR_SET_PDEATHSIG, signal.SIGKILL)


def shard_file(work_dir, k, n):
    return os.path.join(work_dir, f"shard-{k:05d}-of-{n:05d}.jsonl")


def run_shard(binary, k, n, inputs, flags, work_dir, jobs, cwd, command="batch"):
    """One Ray task: one shard, resumed from its file if an earlier attempt left one.
    Returns (k, the shard file's bytes, the batch's last stderr lines)."""
    os.makedirs(work_dir, exist_ok=True)
    out = shard_file(work_dir, k, n)
    cmd = [binary, command, "--shard", f"{k}/{n}", "--resume", "--out", out,
           "--jobs", str(jobs), *flags, *inputs]
    # From the driver's folder, so the inputs' paths (and the lines' `batch.input`) read as
    # they do for a plain `batch` run there.
    p = subprocess.run(cmd, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                       stderr=subprocess.PIPE, preexec_fn=die_with_parent())
    err = p.stderr.decode("utf-8", "replace").strip().splitlines()
    summary = [l for l in err if l.startswith(f"{command}: ")]
    tail = summary[-1:] or [l for l in err if not l.startswith("[")][-3:]
    # 0, 1 and 2 are the batch's answers (2: an object has an error line) when it got to its
    # summary; anything else (a signal, a batch that stopped before running) is a failure
    # that Ray retries.
    finished = bool(summary)
    if p.returncode not in (0, 1, 2) or not finished:
        raise RuntimeError(f"shard {k}/{n}: {' '.join(cmd)} exited {p.returncode}: "
                           + " | ".join(tail))
    with open(out, "rb") as f:
        data = f.read()
    crash = os.environ.get("GRASP_SIM_RAY_TEST_CRASH_SHARD")
    marker = out + ".test-crashed"
    if crash == str(k) and not os.path.exists(marker):
        # Test hook (tests/it/ray.rs): lose this worker once after its shard ran, as a lost
        # node would, to show that Ray retries the task and the retry resumes the shard.
        open(marker, "w").close()
        os.kill(os.getpid(), signal.SIGKILL)
    return k, data, tail


def main():
    argv = sys.argv[1:]
    flags = []
    if "--" in argv:
        i = argv.index("--")
        argv, flags = argv[:i], argv[i + 1:]
    ap = argparse.ArgumentParser(
        description="Run a grasp-sim batch as Ray tasks (shards), merge and check it.",
        epilog="Flags after -- go to every `grasp-sim batch` (e.g. -- --no-sim --template t.toml).")
    ap.add_argument("inputs", nargs="+", help="folders, scenarios or meshes, as for `batch`")
    ap.add_argument("--out", required=True, help="the merged results (JSON Lines)")
    ap.add_argument("--binary", default="target/release/grasp-sim",
                    help="the grasp-sim binary (default: %(default)s)")
    ap.add_argument("--address", default=None,
                    help="a running Ray cluster (`auto`, `ray://host:10001`); default: start one here")
    ap.add_argument("--num-cpus", type=int, default=None,
                    help="CPUs of the local Ray instance (without --address; default: all)")
    ap.add_argument("--cpus-per-task", type=int, default=1,
                    help="Ray num_cpus of each task, and its batch --jobs (default: %(default)s)")
    ap.add_argument("--shards", type=int, default=None,
                    help="number of tasks (default: 4 per task slot of the cluster)")
    ap.add_argument("--max-retries", type=int, default=3,
                    help="Ray max_retries of each task (default: %(default)s)")
    ap.add_argument("--command", choices=["batch", "label"], default="batch",
                    help="the grasp-sim command each task runs: `batch` (one line per object) "
                         "or `label` (one line per labelled grasp; its flags after --) "
                         "(default: %(default)s)")
    ap.add_argument("--work-dir", default=None,
                    help="where tasks write their shard files (default: OUT.shards)")
    args = ap.parse_args(argv)

    import ray  # imported late: --help works without Ray installed


    binary = os.path.abspath(args.binary)
    if not os.access(binary, os.X_OK):
        print(f"ray_batch: error: {args.binary}: no such program (build it: cargo build --release)",
              file=sys.stderr)
        return 2
    out = os.path.abspath(args.out)
    work_dir = os.path.abspath(args.work_dir or out + ".shards")
    gathered = out + ".gathered"
    inputs = args.inputs
    cwd = os.getcwd()

    t0 = time.monotonic()
    if args.address:
        ray.init(address=args.address, log_to_driver=False)
    else:
        # "local": always a new instance here, never one that happens to run on this machine.
        ray.init(address="local", num_cpus=args.num_cpus, include_dashboard=False,
                 log_to_driver=False)
    # SIGTERM (a scheduler, `kill`) stops the local instance before the driver exits (set
    # after ray.init, which installs its own handler). After a SIGKILL nothing can: a local
    # instance may leave agent processes behind.
    def on_term(*_):
        print("ray_batch: stopped (SIGTERM); the same command continues the run", file=sys.stderr)
        ray.shutdown()
        os._exit(143)
    signal.signal(signal.SIGTERM, on_term)
    cpus = int(ray.cluster_resources().get("CPU", 1))
    slots = max(1, cpus // max(1, args.cpus_per_task))
    n = args.shards or 4 * slots
    t_ray = time.monotonic() - t0
    print(f"ray_batch: {cpus} CPUs, {n} shards of {len(inputs)} input(s), "
          f"{args.cpus_per_task} CPU(s) per task (Ray up in {t_ray:.1f} s)", file=sys.stderr)

    task = ray.remote(run_shard).options(
        num_cpus=args.cpus_per_task, max_retries=args.max_retries, retry_exceptions=True)
    pending = [task.remote(binary, k, n, inputs, flags, work_dir, args.cpus_per_task, cwd,
                           args.command)
               for k in range(1, n + 1)]
    os.makedirs(gathered, exist_ok=True)
    for old in os.listdir(gathered):
        if old.endswith(".jsonl"):
            os.remove(os.path.join(gathered, old))
    failed = []
    while pending:
        done, pending = ray.wait(pending, num_returns=1)
        try:
            k, data, tail = ray.get(done[0])
        except Exception as e:  # a task that failed every retry
            failed.append(str(e).strip().splitlines()[-1])
            continue
        with open(shard_file(gathered, k, n), "wb") as f:
            f.write(data)
        print(f"ray_batch: shard {k}/{n}: " + " | ".join(tail), file=sys.stderr)
    t_run = time.monotonic() - t0
    ray.shutdown()
    for f in failed:
        print(f"ray_batch: error: {f}", file=sys.stderr)

    merge = subprocess.run([binary, args.command, "--merge", gathered, "--out", out, *flags, *inputs],
                           stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE)
    merge_err = merge.stderr.decode("utf-8", "replace")
    sys.stderr.write(merge_err)
    wrote = f"wrote {args.out}" if "merge check failed" not in merge_err else "nothing written"
    print(f"ray_batch: {len(failed)} failed task(s); shards ran in {t_run:.1f} s, "
          f"{time.monotonic() - t0:.1f} s in all; {wrote}", file=sys.stderr)
    return merge.returncode if not failed or merge.returncode == 2 else 2


if __name__ == "__main__":
    sys.exit(main())
