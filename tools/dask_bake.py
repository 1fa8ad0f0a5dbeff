#!/usr/bin/python3
"""Runs a sharded hemilight_bake on a Dask cluster.

Usage:
    dask_bake.py [MODEL] --shards S [--scheduler tcp://HOST:8786 | --workers W]
                 [--hemilight-bake PATH] [--task-stream FILE] [--quiet]
                 [hemilight_bake options] --out DIR

Writes into DIR the same files, byte for byte, as

    hemilight_bake [MODEL] --shards S [hemilight_bake options] --out DIR

(the lightmaps, masks, previews and whatever the options ask for). Without MODEL it bakes
hemilight_bake's built-in scenes, like hemilight_bake.

How: the bake has one pass per bounce (--bounces, default 3). Each pass K is S jobs on the
cluster, one task per shard, each running `hemilight_bake --shard I/S --pass K` in a fresh
temporary directory on its worker. The driver then merges the pass in its own process
(`hemilight_bake --merge K --shards S`): the merged state is what the next pass's jobs read, and
the merge of the last pass writes the bake's files.

Transfer: the files go through Dask. A task gets the previous pass's state as bytes (scattered
to every worker once per pass), writes it into its temporary directory, and returns the files its
job wrote as bytes. Workers need not share a writable file system with the driver or with each
other; they only read MODEL (and --environment, --probes files) and the hemilight_bake binary
from the same absolute paths as the driver, as from a shared or synced install.

Options of this driver (everything else goes to every hemilight_bake call unchanged, and must be
the same for every job and merge, which the driver ensures):
    --shards S            shards per pass, 1..4096 (required)
    --scheduler ADDR      the Dask scheduler to use; without it the driver starts a local
                          cluster of --workers single-thread worker processes (default 2)
    --workers W           worker processes of the local cluster
    --hemilight-bake PATH the binary (default: $HEMILIGHT_BAKE, else
                          ../build/examples/hemilight_bake beside this script, else on PATH)
    --out DIR             output directory (default out)
    --task-stream FILE    also write Dask's task-stream records (task key, worker, start and stop
                          times) as JSON
    --quiet               no progress lines and no merge output

Failure: a task whose job fails is retried; a task whose worker dies is run again elsewhere (Dask
reschedules it; a job dies with its worker). The jobs are deterministic, so a re-run gives the
same bits. If every worker holding the scattered state died, the scheduler cancels the pass's
tasks and the driver scatters the state again and resubmits them. If a shard still
fails, the driver cancels the pass's other tasks, prints the job's stderr and exits with status 1
(2 when hemilight_bake refused the options), writing nothing into DIR. The last merge runs in a
temporary directory inside DIR and its files are moved into DIR only when it succeeded.
"""

import glob
import json
import logging
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import uuid

import distributed

usage = """\
usage: dask_bake.py [MODEL] --shards S [--scheduler ADDR | --workers W] [--hemilight-bake PATH]
                    [--task-stream FILE] [--quiet] [hemilight_bake options] --out DIR
  Runs hemilight_bake's sharded bake (--shards S) on a Dask cluster: the same files, byte for byte.
driver options:
  --shards S            shards per pass, 1..4096 (required)
  --scheduler ADDR      a running Dask scheduler (tcp://HOST:8786); default: a local cluster
  --workers W           worker processes of the local cluster, one thread each (default 2)
  --hemilight-bake PATH the binary (default: $HEMILIGHT_BAKE, else ../build/examples/hemilight_bake
                        beside this script, else hemilight_bake on PATH)
  --out DIR             output directory (default out)
  --task-stream FILE    also write the Dask task stream (key, worker, start/stop times) as JSON
  --quiet               no progress lines, no merge summary
  --help                this text
Every other option goes to every hemilight_bake call (see hemilight_bake --help); --bounces K sets
the number of passes (default 3).
"""

max_shards = 4096  # hemilight_bake's limit
retries = 2        # re-runs of a task whose job failed (a worker's death is Dask's to handle)
resubmits = 3      # fresh submissions of a shard whose task was cancelled under us (lost input)

# hemilight_bake's options that take a value (the next argument), to tell MODEL from the values.
# --preview takes a camera only when the next argument reads as one (it has commas).
value_options = {"--size", "--resolution", "--error", "--bounces", "--threads", "--sky", "--directional",
                 "--environment", "--sun", "--point", "--ao", "--probes", "--lightmap-uv", "--texels-per-unit"}
# Options the driver sets for each call itself.
reserved_options = {"--shard", "--pass", "--merge"}

# The files of a sharded bake: a shard's (NAME_passK_shardIofS) and a pass's state (NAME_passK).
shard_file = re.compile(r"^.+_pass(\d+)_shard(\d+)of(\d+)\.(exr|json)$")
state_file = re.compile(r"^.+_pass(\d+)\.(exr|json)$")


class UsageError(Exception):
    """A bad command line (exit status 2)."""
    code = 2


class BakeError(Exception):
    """A bake that cannot be done or did not succeed (exit status `code`, 1 unless set)."""

    def __init__(self, message, code=1):
        super().__init__(message)
        self.code = code


class Args:
    """The parsed command line: the driver's settings and the arguments for hemilight_bake."""

    def __init__(self):
        self.shards = None        # --shards S
        self.scheduler = None     # --scheduler ADDR (None: a local cluster)
        self.workers = None       # --workers W (None: 2)
        self.binary = None        # --hemilight-bake PATH (None: the default search)
        self.out = "out"          # --out DIR
        self.task_stream = None   # --task-stream FILE
        self.quiet = False        # --quiet
        self.model = None         # MODEL, absolute after prepare()
        self.model_index = None   # where MODEL is in `forwarded`
        self.bounces = 3          # --bounces K: the number of passes
        self.forwarded = []       # every other argument, in order, MODEL and file paths absolute


def _parse_int(name, text, lo, hi):
    try:
        value = int(text, 10)
    except ValueError:
        value = None
    if value is None or not lo <= value <= hi:
        raise UsageError(f"{name} {text} is invalid: it must be an integer in [{lo}, {hi}]")
    return value


def _absolute_if_file(path):
    return os.path.abspath(path) if os.path.isfile(path) else path


def parse_args(argv):
    """Parses the command line (without the program name) into Args; raises UsageError.
    --help prints the usage and exits."""
    a = Args()
    i = 0
    while i < len(argv):
        arg = argv[i]

        def value():
            nonlocal i
            if i + 1 >= len(argv):
                raise UsageError(f"{arg} needs a value (see --help)")
            i += 1
            return argv[i]

        if arg in ("--help", "-h"):
            sys.stdout.write(usage)
            raise SystemExit(0)
        elif arg == "--shards":
            a.shards = _parse_int("--shards", value(), 1, max_shards)
        elif arg == "--scheduler":
            a.scheduler = value()
        elif arg == "--workers":
            a.workers = _parse_int("--workers", value(), 1, 1024)
        elif arg == "--hemilight-bake":
            a.binary = value()
        elif arg == "--out":
            a.out = value()
        elif arg == "--task-stream":
            a.task_stream = value()
        elif arg == "--quiet":
            a.quiet = True
        elif arg in reserved_options:
            raise UsageError(f"{arg} is the driver's to set for each job and merge; give --shards S only")
        elif arg in value_options:
            v = value()
            if arg == "--bounces":
                a.bounces = _parse_int("--bounces", v, 1, 64)
            elif arg in ("--environment", "--probes"):
                v = _absolute_if_file(v)  # --probes is a grid (8x4x8) or a file of points
            a.forwarded += [arg, v]
        elif arg == "--preview":
            a.forwarded.append(arg)
            if i + 1 < len(argv) and not argv[i + 1].startswith("-") and "," in argv[i + 1]:
                i += 1
                a.forwarded.append(argv[i])  # the camera
        elif arg.startswith("-") and len(arg) > 1:
            a.forwarded.append(arg)  # a flag; hemilight_bake judges it
        elif a.model is None:
            a.model, a.model_index = arg, len(a.forwarded)
            a.forwarded.append(arg)
        else:
            raise UsageError(f"more than one model given: {a.model} and {arg}")
        i += 1
    if a.shards is None:
        raise UsageError("--shards S is required (the shards of each pass, 1..4096)")
    if a.scheduler is not None and a.workers is not None:
        raise UsageError("--workers sizes the local cluster; it cannot be used with --scheduler")
    return a


def find_binary(path=None):
    """The hemilight_bake to run, as an absolute path: `path`, else $HEMILIGHT_BAKE, else
    ../build/examples/hemilight_bake beside this script, else hemilight_bake on PATH."""
    if path is None:
        path = os.environ.get("HEMILIGHT_BAKE")
    if path is None:
        beside = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "examples", "hemilight_bake")
        path = beside if os.path.isfile(beside) else shutil.which("hemilight_bake")
        if path is None:
            raise BakeError("hemilight_bake not found (give --hemilight-bake PATH or set HEMILIGHT_BAKE)")
    if not os.path.isfile(path) or not os.access(path, os.X_OK):
        raise BakeError(f"hemilight_bake not found: '{path}' is not an executable file")
    return os.path.abspath(path)


def prepare(args):
    """Checks what the driver can check before any work, and makes the paths absolute: the binary,
    MODEL (the jobs run in other directories, maybe on other machines), DIR writable."""
    args.binary = find_binary(args.binary)
    if args.model is not None:
        args.model = args.forwarded[args.model_index] = os.path.abspath(args.model)
        if not os.path.isfile(args.model):
            raise BakeError(f"model not found: '{args.model}'")
    for option, value in zip(args.forwarded, args.forwarded[1:]):
        if option == "--environment" and not os.path.isfile(value):
            raise BakeError(f"environment map not found: '{value}'")
    out = os.path.abspath(args.out)
    if os.path.exists(out) and not os.path.isdir(out):
        raise BakeError(f"the output directory '{args.out}' is a file")
    existing = out
    while not os.path.exists(existing):
        existing = os.path.dirname(existing)
    if not os.path.isdir(existing) or not os.access(existing, os.W_OK | os.X_OK):
        raise BakeError(f"cannot write the output directory '{args.out}' ('{existing}' is not writable)")
    return args


def run_job(binary, forwarded, pass_number, shard, shards, state):
    """One task, on a worker: runs `hemilight_bake --shard I/S --pass K` in a fresh temporary
    directory holding the previous pass's state (`state`: file name -> bytes, or None for pass 1).
    Returns {"files": {name: bytes}, "worker", "seconds", "hemicubes"}, or {"usage_error": stderr}
    when hemilight_bake refused the options (exit status 2, the same on every try). Raises
    RuntimeError with the job's stderr on any other failure, so that Dask retries the task."""
    import ctypes

    try:
        worker = distributed.get_worker()
        address, base = worker.address, worker.local_directory
    except ValueError:  # not on a worker (called directly)
        address, base = "local", None
    job = f"pass {pass_number} shard {shard}/{shards}"
    # The job dies with this worker (a killed worker would otherwise leave it running).
    preexec = None
    if sys.platform.startswith("linux"):
        try:
            prctl, parent = ctypes.CDLL(None, use_errno=True).prctl, os.getpid()

            def preexec():
                prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG
                if os.getppid() != parent:
                    os._exit(1)
        except (OSError, AttributeError):
            preexec = None
    start = time.monotonic()
    with tempfile.TemporaryDirectory(prefix=f"hemilight-pass{pass_number}-shard{shard}-", dir=base) as tmp:
        for name, data in (state or {}).items():
            with open(os.path.join(tmp, os.path.basename(name)), "wb") as f:
                f.write(data)
        command = [binary, *forwarded, "--shard", f"{shard}/{shards}", "--pass", str(pass_number), "--quiet", "--out", tmp]
        try:
            p = subprocess.run(command, cwd=tmp, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, preexec_fn=preexec)
        except OSError as e:
            raise RuntimeError(f"{job} on {address}: cannot run '{binary}': {e}") from None
        stderr = p.stderr.decode(errors="replace").strip()
        if p.returncode == 2:
            return {"usage_error": stderr, "worker": address}
        if p.returncode != 0:
            how = f"exit status {p.returncode}" if p.returncode > 0 else f"signal {-p.returncode}"
            raise RuntimeError(f"{job} on {address}: hemilight_bake failed ({how}):\n{stderr}")
        files = {}
        for path in sorted(glob.glob(os.path.join(glob.escape(tmp), f"*_pass{pass_number}_shard{shard}of{shards}.*"))):
            with open(path, "rb") as f:
                files[os.path.basename(path)] = f.read()
    if not files:
        raise RuntimeError(f"{job} on {address}: hemilight_bake wrote no shard files")
    hemicubes = sum(json.loads(data).get("hemicubes", 0) for name, data in files.items() if name.endswith(".json"))
    return {"files": files, "worker": address, "seconds": time.monotonic() - start, "hemicubes": hemicubes}


def task_key(bake_id, pass_number, shard, attempt=0):
    """The Dask key of a shard's task: pass{K}-shard{I}, made unique to this bake (and to a fresh
    submission) so that bakes sharing a scheduler never share results."""
    key = f"pass{pass_number}-shard{shard}-{bake_id}"
    return key if attempt == 0 else f"{key}-{attempt}"


def _log(args, line):
    if not args.quiet:
        print(line, file=sys.stderr, flush=True)


def run_pass(client, args, pass_number, state, bake_id, records):
    """Pass K on the cluster: the state scattered once to every worker, one task per shard.
    Returns every shard's files (name -> bytes); appends one record per task to `records`.
    On a failure cancels the pass's other tasks and raises BakeError."""
    S = args.shards
    state_future = None

    def scatter():
        nonlocal state_future
        if state is not None:
            [state_future] = client.scatter([state], broadcast=True, hash=False)

    def submit(shard, attempt):
        future = client.submit(run_job, args.binary, args.forwarded, pass_number, shard, S, state_future,
                               key=task_key(bake_id, pass_number, shard, attempt), pure=False, retries=retries)
        shard_of[future] = (shard, attempt)
        pending.add(future)
        return future

    shard_of, pending, files = {}, set(), {}
    scatter()
    for shard in range(S):
        submit(shard, 0)
    completed = distributed.as_completed(list(pending))
    try:
        for future in completed:
            pending.discard(future)
            shard, attempt = shard_of[future]
            job = f"pass {pass_number} shard {shard}/{S}"
            if future.status == "cancelled":
                # Not by us: an input was lost (every worker holding the scattered state died).
                if attempt >= resubmits:
                    raise BakeError(f"{job} was cancelled by the scheduler {attempt + 1} times (its input was lost)")
                _log(args, f"{job}: cancelled by the scheduler, submitting it again")
                if state_future is not None and state_future.status != "finished":
                    scatter()
                completed.add(submit(shard, attempt + 1))
                continue
            try:
                r = future.result()
            except RuntimeError as e:  # run_job's failures name the job and carry its stderr
                raise BakeError(str(e)) from None
            except Exception as e:  # e.g. KilledWorker: the task's workers kept dying
                raise BakeError(f"{job} failed: {type(e).__name__}: {e}") from None
            if "usage_error" in r:
                raise BakeError(f"hemilight_bake refused the options:\n{r['usage_error']}", code=2)
            files.update(r["files"])
            records.append({"pass": pass_number, "shard": shard, "key": future.key, "worker": r["worker"],
                            "seconds": r["seconds"], "hemicubes": r["hemicubes"]})
            _log(args, f"pass {pass_number}/{args.bounces} shard {shard}/{S}: {r['seconds']:.2f} s on {r['worker']}"
                       f" ({r['hemicubes']} hemicubes)")
    except BaseException:
        if pending:
            client.cancel(list(pending))
        raise
    return files


def run_merge(args, pass_number, directory):
    """`hemilight_bake --merge K --shards S` in `directory` (which holds its inputs), in this
    process. Returns its standard output; raises BakeError with its stderr if it fails."""
    command = [args.binary, *args.forwarded, "--merge", str(pass_number), "--shards", str(args.shards), "--quiet",
               "--out", directory]
    try:
        p = subprocess.run(command, cwd=directory, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    except OSError as e:
        raise BakeError(f"cannot run '{args.binary}': {e}") from None
    if p.returncode != 0:
        how = f"exit status {p.returncode}" if p.returncode > 0 else f"signal {-p.returncode}"
        raise BakeError(f"the merge of pass {pass_number} failed ({how}):\n{p.stderr.decode(errors='replace').strip()}",
                        code=2 if p.returncode == 2 else 1)
    return p.stdout.decode(errors="replace")


def _write_files(directory, files):
    for name, data in files.items():
        with open(os.path.join(directory, os.path.basename(name)), "wb") as f:
            f.write(data)


def _link_or_copy(source, target):
    try:
        os.link(source, target)
    except OSError:
        shutil.copyfile(source, target)


def final_merge(args, work):
    """The last pass's merge, in a temporary directory inside DIR holding its inputs (from the
    driver's directory `work`); its files are moved into DIR only when it succeeded. Returns the
    merge's standard output, with DIR in place of the temporary directory."""
    out = os.path.abspath(args.out)
    created = not os.path.isdir(out)
    os.makedirs(out, exist_ok=True)
    final = tempfile.mkdtemp(prefix=".dask_bake-", dir=out)
    done = False
    try:
        inputs = set()
        for name in os.listdir(work):
            if shard_file.match(name) or state_file.match(name):
                _link_or_copy(os.path.join(work, name), os.path.join(final, name))
                inputs.add(name)
        output = run_merge(args, args.bounces, final)
        for name in sorted(os.listdir(final)):
            if name not in inputs:
                os.replace(os.path.join(final, name), os.path.join(out, name))
        done = True
    finally:
        shutil.rmtree(final, ignore_errors=True)
        if created and not done:
            try:
                os.rmdir(out)
            except OSError:
                pass
    return output.replace(final, out)


def _bake_passes(client, args, records):
    S, B = args.shards, args.bounces
    bake_id = uuid.uuid4().hex[:12]
    workers = len(client.scheduler_info().get("workers", {}))
    _log(args, f"dask_bake: {os.path.basename(args.model) if args.model else 'the built-in scenes'}: {B} pass"
               f"{'es' if B > 1 else ''} of {S} shard{'s' if S > 1 else ''} on {client.scheduler.address} "
               f"({workers} worker{'s' if workers != 1 else ''}{'; waiting for one' if workers == 0 else ''})")
    with tempfile.TemporaryDirectory(prefix="dask_bake-") as work:
        state = None
        for K in range(1, B + 1):
            files = run_pass(client, args, K, state, bake_id, records)
            _write_files(work, files)
            if K == B:
                return final_merge(args, work)
            output = run_merge(args, K, work)
            for line in output.splitlines():
                _log(args, line)
            state = {}
            for name in os.listdir(work):
                m = state_file.match(name)
                if m and int(m.group(1)) == K:
                    with open(os.path.join(work, name), "rb") as f:
                        state[name] = f.read()
            if not state:
                raise BakeError(f"the merge of pass {K} wrote no state (no *_pass{K}.exr)")
            # Kept: pass 1's shards (every merge reads them) and this state (the next merge reads it).
            for name in os.listdir(work):
                m, n = shard_file.match(name), state_file.match(name)
                if (m and int(m.group(1)) == K and K > 1) or (n and int(n.group(1)) == K - 1):
                    os.remove(os.path.join(work, name))


def _task_stream_json(data, records):
    keys = {r["key"] for r in records}
    rows = []
    for t in data:
        key = t.get("key")
        if key not in keys:
            continue
        startstops = [{"action": s.get("action"), "start": s.get("start"), "stop": s.get("stop")}
                      for s in t.get("startstops", ())]
        compute = [s for s in startstops if s["action"] == "compute"]
        rows.append({"key": key, "worker": t.get("worker"), "status": t.get("status"),
                     "start": compute[0]["start"] if compute else None,
                     "stop": compute[-1]["stop"] if compute else None, "startstops": startstops})
    return rows


def bake(client, args):
    """The whole bake on `client`'s cluster; `args` from parse_args (prepare() is applied here).
    Returns one record per task: {"pass", "shard", "key", "worker", "seconds", "hemicubes"}.
    Raises BakeError (or UsageError) on failure, having written nothing into DIR."""
    prepare(args)
    if __name__ != "__main__":
        # Imported (as by the tests): send run_job by value, so that workers need not import this file.
        import cloudpickle
        cloudpickle.register_pickle_by_value(sys.modules[__name__])
    records = []
    if not args.task_stream:
        output = _bake_passes(client, args, records)
    else:
        with distributed.get_task_stream(client=client) as stream:
            output = _bake_passes(client, args, records)
        with open(args.task_stream, "w") as f:
            json.dump(_task_stream_json(stream.data, records), f, indent=1)
            f.write("\n")
    if not args.quiet:
        sys.stdout.write(output)
        sys.stdout.flush()
    return records


def connect(args):
    """A Client of --scheduler, or of a new local cluster of --workers single-thread processes.
    Returns (client, cluster or None); raises BakeError when the scheduler cannot be reached."""
    if args.scheduler is not None:
        try:
            return distributed.Client(args.scheduler), None
        except (OSError, TimeoutError) as e:
            raise BakeError(f"cannot reach the Dask scheduler at {args.scheduler}: {e}") from None
    workers = args.workers or 2
    cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=":0", silence_logs=logging.ERROR)
    client = distributed.Client(cluster)
    try:
        client.wait_for_workers(workers, timeout=120)
    except (TimeoutError, OSError) as e:
        client.close()
        cluster.close()
        raise BakeError(f"the local cluster's {workers} worker processes did not start: {e}") from None
    return client, cluster


def main(argv=None):
    """The command line: returns the exit status (0, 1 for a failed bake, 2 for bad arguments)."""
    if threading.current_thread() is threading.main_thread():
        # A terminated driver still cancels its tasks, closes its cluster and removes its files.
        signal.signal(signal.SIGTERM, lambda number, frame: sys.exit(128 + number))
    try:
        args = parse_args(sys.argv[1:] if argv is None else argv)
        prepare(args)
        client, cluster = connect(args)
        try:
            bake(client, args)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    except (UsageError, BakeError) as e:
        print(f"dask_bake: {e}", file=sys.stderr)
        return e.code
    return 0


if __name__ == "__main__":
    sys.exit(main())
