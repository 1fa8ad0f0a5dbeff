#!/usr/bin/python3
"""tools/dask_bake.py against the one-process sharded bake (hemilight_bake --shards S), and the
refusals of hemilight_bake's shard modes (--shard I/S --pass K, --merge K).

Run with Debian's python (it has dask and distributed):
    HEMILIGHT_BAKE=build/examples/hemilight_bake HEMILIGHT_MAKE_LEVEL=build/examples/hemilight_make_level \
        /usr/bin/python3 tests/test_dask_bake.py [-v] [TestClass.test_name]
Without the variables the binaries are taken from build/examples/ in this source tree.
"""

import filecmp
import json
import logging
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import warnings

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(here)
sys.path.insert(0, os.path.join(root, "tools"))

import distributed  # noqa: E402

import dask_bake  # noqa: E402

BAKE = os.environ.get("HEMILIGHT_BAKE", os.path.join(root, "build", "examples", "hemilight_bake"))
MAKE_LEVEL = os.environ.get("HEMILIGHT_MAKE_LEVEL", os.path.join(root, "build", "examples", "hemilight_make_level"))
DRIVER = os.path.join(root, "tools", "dask_bake.py")

# The arena's sun and sky, as hemilight_make_level prints them.
SUN = ["--sun", "-0.55667,-0.766044,-0.321394,20,0.00465", "--sky", "1,1,1"]


def wait_for(path, seconds=300):
    """The binaries may be rebuilt while the tests start: wait for them to be back."""
    deadline = time.monotonic() + seconds
    while not os.access(path, os.X_OK):
        if time.monotonic() > deadline:
            raise unittest.SkipTest(f"{path} is not built")
        time.sleep(2)


def setUpModule():
    warnings.filterwarnings("ignore", category=DeprecationWarning, module="tornado")  # a local cluster's start
    wait_for(BAKE)
    wait_for(MAKE_LEVEL)


def run(command, **kw):
    """Runs a command; returns (exit status, stdout, stderr) as text."""
    p = subprocess.run(command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, **kw)
    return p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")


def bake_cli(*args, check=True):
    """hemilight_bake with `args` (no progress bar)."""
    rc, out, err = run([BAKE, *args, "--quiet"])
    if check and rc != 0:
        raise AssertionError(f"hemilight_bake {' '.join(args)} failed ({rc}):\n{err}")
    return rc, out, err


def driver(*args, env=None, cwd=None):
    """tools/dask_bake.py with `args`, in its own process; returns (status, stdout, stderr)."""
    e = dict(os.environ, HEMILIGHT_BAKE=BAKE)
    e.update(env or {})
    return run([sys.executable, DRIVER, *args], env=e, cwd=cwd)


def make_level(name, path):
    """The smallest stand-in level of its kind: 10,000 triangles aimed at, UVs for 256 x 256."""
    rc, out, err = run([MAKE_LEVEL, name, path, "--triangles", "10000", "--lightmap-size", "256"])
    if rc != 0:
        raise AssertionError(f"hemilight_make_level {name} failed ({rc}):\n{err}")


def files(directory):
    return sorted(os.listdir(directory))


def one_line(text):
    """The single line of a refusal's stderr."""
    lines = text.strip().splitlines()
    assert len(lines) == 1, f"expected one line, got:\n{text}"
    return lines[0]


class TempDir(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="test_dask_bake-")
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def path(self, *parts):
        return os.path.join(self.tmp, *parts)

    def assertSameFiles(self, a, b):
        """The same file names in a and b, and every file byte-identical."""
        self.assertTrue(files(a), f"{a} is empty")
        self.assertEqual(files(a), files(b))
        for name in files(a):
            self.assertTrue(filecmp.cmp(os.path.join(a, name), os.path.join(b, name), shallow=False),
                            f"{name} differs between {a} and {b}")


class BuiltInScenes(TempDir):
    def test_same_files_as_the_one_process_sharded_bake(self):
        options = ["--size", "32", "--bounces", "2", "--threads", "1"]
        bake_cli("--shards", "3", *options, "--out", self.path("A"))
        stream = self.path("stream.json")
        rc, out, err = driver("--shards", "3", "--workers", "2", *options, "--task-stream", stream, "--out",
                              self.path("B"))
        self.assertEqual(rc, 0, err)
        self.assertSameFiles(self.path("A"), self.path("B"))
        # One progress line per task, and the task stream's records of the 2 x 3 tasks.
        for k in (1, 2):
            for i in range(3):
                self.assertIn(f"pass {k}/2 shard {i}/3: ", err)
        with open(stream) as f:
            records = json.load(f)
        self.assertEqual(sorted(r["key"].rsplit("-", 1)[0] for r in records),
                         sorted(f"pass{k}-shard{i}" for k in (1, 2) for i in range(3)))
        for r in records:
            self.assertTrue(r["worker"].startswith("tcp://"))
            self.assertLessEqual(r["start"], r["stop"])


class StandInLevel(TempDir):
    def setUp(self):
        super().setUp()
        make_level("arena", self.path("arena.glb"))

    def test_arena_with_sun_ao_and_directional(self):
        # Three passes: the merges of passes 2 and 3 read pass 1's shards and the state before them.
        options = ["--size", "64", "--bounces", "3", "--threads", "1", *SUN, "--ao", "2", "--shadow-mask",
                   "--directional", "both"]
        bake_cli(self.path("arena.glb"), "--shards", "3", *options, "--out", self.path("A"))
        # A relative MODEL: the driver makes it absolute for the workers.
        rc, out, err = driver("arena.glb", "--shards", "3", "--workers", "3", *options, "--quiet", "--out", "B",
                              cwd=self.tmp)
        self.assertEqual(rc, 0, err)
        self.assertEqual(out, "")  # --quiet
        self.assertIn("arena_ao.exr", files(self.path("A")))
        self.assertIn("arena_shadow_mask.exr", files(self.path("A")))
        self.assertSameFiles(self.path("A"), self.path("B"))

    def test_generated_uvs_in_pages(self):
        # New lightmap UVs spilling into several pages (NAME_pageP_*, NAME_lightmap_uvs.glb), a preview.
        options = ["--size", "64", "--bounces", "1", "--threads", "1", "--generate-uvs", "--texels-per-unit", "0.6",
                   "--preview"]
        bake_cli(self.path("arena.glb"), "--shards", "2", *options, "--out", self.path("A"))
        rc, out, err = driver(self.path("arena.glb"), "--shards", "2", "--workers", "2", *options, "--out",
                              self.path("B"))
        self.assertEqual(rc, 0, err)
        self.assertIn("arena_lightmap_uvs.glb", files(self.path("A")))
        self.assertIn("arena_page1_irradiance.exr", files(self.path("A")))
        self.assertIn("arena_preview.png", files(self.path("A")))
        self.assertSameFiles(self.path("A"), self.path("B"))


class WorkerKilled(TempDir):
    """A worker SIGKILLed while it runs a job of pass 2: Dask runs the task again elsewhere; the
    result stays byte-identical."""

    # No cache at 128 x 128: each job of a pass takes seconds, so the kill lands inside one.
    options = ["--size", "128", "--bounces", "2", "--no-cache", *SUN]

    def bake_and_kill(self, workers):
        """Bakes the arena with 2 shards on a local cluster of `workers`, kills the worker of a job
        of pass 2, and checks the bake against the one-process sharded bake. Returns the records."""
        make_level("arena", self.path("arena.glb"))
        bake_cli(self.path("arena.glb"), "--shards", "2", *self.options, "--threads", "2", "--out", self.path("A"))
        args = dask_bake.parse_args([self.path("arena.glb"), "--shards", "2", *self.options, "--threads", "1", "--quiet",
                                     "--hemilight-bake", BAKE, "--out", self.path("B")])
        with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                                      silence_logs=logging.CRITICAL) as cluster, distributed.Client(cluster) as client:
            outcome = {}

            def target():
                try:
                    outcome["records"] = dask_bake.bake(client, args)
                except BaseException as e:  # reported by the main thread
                    outcome["error"] = e

            thread = threading.Thread(target=target)
            thread.start()
            # Wait for a job of pass 2 running on a worker.
            victim = key = None
            deadline = time.monotonic() + 240
            while victim is None and thread.is_alive() and time.monotonic() < deadline:
                for worker, keys in client.processing().items():
                    running = [k for k in keys if str(k).startswith("pass2-")]
                    if running:
                        victim, key = worker, running[0]
                        break
                else:
                    time.sleep(0.05)
            self.assertIsNotNone(victim, f"no job of pass 2 was seen processing ({outcome})")
            pid = client.run(os.getpid, workers=[victim])[victim]
            local = client.run(lambda dask_worker: dask_worker.local_directory, workers=[victim])[victim]
            still = client.processing().get(victim, ())
            os.kill(pid, signal.SIGKILL)
            self.assertIn(key, still, "the job finished before the kill")
            # The killed worker's job dies with it (no orphan left writing into its directory).
            deadline = time.monotonic() + 10
            while any(local in c for c in hemilight_command_lines()) and time.monotonic() < deadline:
                time.sleep(0.2)
            self.assertFalse(any(local in c for c in hemilight_command_lines()), "the killed worker's job lives on")
            thread.join(600)
            self.assertFalse(thread.is_alive(), "the bake did not finish")
            if "error" in outcome:
                raise outcome["error"]
        records = outcome["records"]
        self.assertEqual(sorted((r["pass"], r["shard"]) for r in records), [(1, 0), (1, 1), (2, 0), (2, 1)])
        killed_shard = int(key.split("-")[1][len("shard"):])
        [rerun] = [r for r in records if r["pass"] == 2 and r["shard"] == killed_shard]
        self.assertNotEqual(rerun["worker"], victim)
        self.assertSameFiles(self.path("A"), self.path("B"))
        return records

    def test_kill_one_of_two_workers(self):
        self.bake_and_kill(2)

    def test_kill_the_only_worker(self):
        # The scattered state of pass 1 dies with it: the scheduler cancels pass 2's tasks, and the
        # driver scatters the state again (to the restarted worker) and submits them again.
        records = self.bake_and_kill(1)
        resubmitted = [r for r in records if r["pass"] == 2 and len(r["key"].split("-")) == 4]  # pass2-shardI-ID-N
        self.assertTrue(resubmitted, records)


def hemilight_command_lines():
    """The command lines of the running hemilight_bake processes."""
    lines = []
    for pid in os.listdir("/proc"):
        if pid.isdigit():
            try:
                with open(f"/proc/{pid}/cmdline", "rb") as f:
                    line = f.read().replace(b"\0", b" ").decode(errors="replace")
            except OSError:
                continue
            if "hemilight_bake" in line:
                lines.append(line)
    return lines


class Refusals(TempDir):
    """hemilight_bake's shard modes refuse inputs that are not this bake's: exit status 1, one
    line naming the file(s), no output."""

    small = ["--size", "16", "--threads", "1"]

    def shards(self, out, shards, which, *options, model=()):
        for i in which:
            bake_cli(*model, *self.small, *options, "--shard", f"{i}/{shards}", "--pass", "1", "--out", out)

    def test_pass2_job_refuses_a_state_of_other_options(self):
        out = self.path("state")
        self.shards(out, 2, range(2), "--bounces", "2")
        bake_cli(*self.small, "--bounces", "2", "--merge", "1", "--shards", "2", "--out", out)
        before = files(out)
        for other in (["--size", "32", "--bounces", "2"], ["--size", "16", "--bounces", "3"]):
            rc, _, err = bake_cli("--threads", "1", *other, "--shard", "0/2", "--pass", "2", "--out", out, check=False)
            self.assertEqual(rc, 1, err)
            line = one_line(err)
            self.assertTrue(line.startswith("hemilight_bake: "), line)
            self.assertIn(os.path.join(out, "hexagon_room_pass1"), line)
            self.assertEqual(files(out), before)

    def test_merge_refuses_a_missing_shard(self):
        out = self.path("missing")
        for bounces in ("1", "2"):  # the final merge, and a merge writing the next pass's state
            self.shards(out, 3, (0, 1), "--bounces", bounces)
            before = files(out)
            rc, _, err = bake_cli(*self.small, "--bounces", bounces, "--merge", "1", "--shards", "3", "--out", out,
                                  check=False)
            self.assertEqual(rc, 1, err)
            line = one_line(err)
            self.assertTrue(line.startswith("hemilight_bake: "), line)
            self.assertIn(os.path.join(out, "hexagon_room_pass1_shard2of3.json"), line)
            self.assertEqual(files(out), before)  # nothing written

    def test_merge_refuses_a_shard_of_another_count(self):
        out, other = self.path("count"), self.path("other")
        self.shards(out, 3, (0, 1))
        self.shards(other, 2, (0,))
        for ext in ("exr", "json"):
            shutil.copyfile(os.path.join(other, f"hexagon_room_pass1_shard0of2.{ext}"),
                            os.path.join(out, f"hexagon_room_pass1_shard2of3.{ext}"))
        before = files(out)
        rc, _, err = bake_cli(*self.small, "--merge", "1", "--shards", "3", "--out", out, check=False)
        self.assertEqual(rc, 1, err)
        line = one_line(err)
        self.assertTrue(line.startswith("hemilight_bake: "), line)
        self.assertIn(os.path.join(out, "hexagon_room_pass1_shard"), line)
        self.assertEqual(files(out), before)

    def test_merge_refuses_a_shard_of_another_model(self):
        out = self.path("model")
        for name in ("arena", "keep"):
            make_level(name, self.path(f"{name}.glb"))
            self.shards(out, 2, range(2), "--bounces", "1", model=[self.path(f"{name}.glb")])
        for ext in ("exr", "json"):
            shutil.copyfile(os.path.join(out, f"keep_pass1_shard1of2.{ext}"), os.path.join(out, f"arena_pass1_shard1of2.{ext}"))
        before = files(out)
        rc, _, err = bake_cli(self.path("arena.glb"), *self.small, "--bounces", "1", "--merge", "1", "--shards", "2",
                              "--out", out, check=False)
        self.assertEqual(rc, 1, err)
        line = one_line(err)
        self.assertTrue(line.startswith("hemilight_bake: "), line)
        self.assertIn(os.path.join(out, "arena_pass1_shard"), line)
        self.assertEqual(files(out), before)


class DriverArguments(TempDir):
    def test_bad_arguments_exit_2(self):
        for args in ([], ["--size", "32"], ["--shards", "0"], ["--shards", "4097"], ["--shards", "x"],
                     ["--shards", "2", "--shard", "0/2"], ["--shards", "2", "--merge", "1"],
                     ["--shards", "2", "--bounces", "0"], ["--shards", "2", "--workers", "0"],
                     ["--shards", "2", "--scheduler", "tcp://127.0.0.1:8786", "--workers", "2"],
                     ["a.glb", "b.glb", "--shards", "2"], ["--shards"]):
            rc, _, err = driver(*args, "--out", self.path("out"))
            self.assertEqual(rc, 2, f"{args}: {err}")
            self.assertTrue(one_line(err).startswith("dask_bake: "), err)
            self.assertFalse(os.path.exists(self.path("out")))

    def test_parse_args(self):
        model = self.path("m.glb")
        open(model, "w").close()
        a = dask_bake.parse_args([model, "--shards", "4", "--size", "32", "--preview", "0,1,2,0,0,0", "--bounces", "2",
                                  "--no-cache", "--workers", "3", "--out", "o", "--quiet"])
        self.assertEqual((a.shards, a.workers, a.bounces, a.out, a.quiet, a.model), (4, 3, 2, "o", True, model))
        self.assertEqual(a.forwarded, [model, "--size", "32", "--preview", "0,1,2,0,0,0", "--bounces", "2", "--no-cache"])
        a = dask_bake.parse_args(["--preview", "rel.glb", "--shards", "1"])
        self.assertEqual((a.model, a.forwarded), ("rel.glb", ["--preview", "rel.glb"]))

    def test_clear_errors_exit_1(self):
        rc, _, err = driver("no_such_model.glb", "--shards", "2", "--out", self.path("out"))
        self.assertEqual(rc, 1, err)
        self.assertIn("model not found", one_line(err))
        rc, _, err = driver("--shards", "2", "--hemilight-bake", self.path("no_such_binary"), "--out", self.path("out"))
        self.assertEqual(rc, 1, err)
        self.assertIn("hemilight_bake not found", one_line(err))
        with socket.socket() as s:  # a port nothing listens on
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        rc, _, err = driver("--shards", "2", "--scheduler", f"tcp://127.0.0.1:{port}", "--out", self.path("out"),
                            env={"DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "3s"})
        self.assertEqual(rc, 1, err)
        self.assertIn("cannot reach the Dask scheduler", one_line(err))
        self.assertFalse(os.path.exists(self.path("out")))

    def test_failed_jobs(self):
        # hemilight_bake refusing an option in its jobs: status 2, its message.
        rc, _, err = driver("--shards", "2", "--workers", "1", "--size", "0", "--out", self.path("out"))
        self.assertEqual(rc, 2, err)
        self.assertIn("hemilight_bake: --size 0 is invalid", err)
        # Jobs that fail (an unreadable environment map): status 1, the job's stderr, nothing in DIR.
        bad = self.path("bad.exr")
        with open(bad, "w") as f:
            f.write("not an EXR file\n")
        rc, _, err = driver("--shards", "2", "--workers", "1", "--size", "16", "--threads", "1", "--environment", bad,
                            "--out", self.path("out"))
        self.assertEqual(rc, 1, err)
        self.assertIn("hemilight_bake: read_exr_cubemap", err)
        self.assertFalse(os.path.exists(self.path("out")))


if __name__ == "__main__":
    unittest.main()
