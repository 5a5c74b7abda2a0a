"""The Python package's speed against the Rust library's, side by side in
one run (issue 19, "Numbers to reach"); scripts/python-bench.sh prepares
the inputs and runs this with the package installed. Three measures:

1. step: `Tracker.step` from Python on 160×120 masks against the Rust
   tracker's own loop (`cargo bench --bench track -- track_clip`), at 9
   primitives × 6 particles and 4 × 200. Both sides decode the same
   folder's silhouettes beforehand, track with the same vocabulary file,
   camera and seed (eq. 10, 15 frames/s), and time a fresh tracker stepped
   through every frame, ten times; the figure is the median pass's time
   per frame (less moved by other processes than the mean; both shown).
   Their winners are compared frame by frame first: the same work.
2. read: `read_bvh(path).positions()` over every BVH of a folder, one file
   after the other, against the Rust library doing the same (read, put on
   the canonical body, forward kinematics for every frame:
   `cargo bench --bench mocap -- read_folder`), and against bvhio (a
   pure-Python BVH reader) reading the same files to every joint's world
   position in every frame.
3. batch: `python -m imitate.batch track` over a folder's clips sent to a
   running local Ray cluster of 2 CPUs (the `side` preset camera for every
   clip: one of the real clips shows no frame an estimated camera can be
   found from), the whole command timed, against the ideal max(slowest
   clip, sum of clips / 2), each clip timed alone as a whole `imitate
   track` command in the same run; beside it, the ideal from each clip
   alone on one CPU and one thread (what a task has), and the command
   starting its own cluster. The run folders are compared (frames.csv
   byte for byte) with the single runs'.

The Rust figures are criterion's median (and mean) estimates, read from
target/criterion/<group>/<name>/new/estimates.json (removed before each
run, so a stale one is never read).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import time
import warnings
import zlib
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

import imitate

#: The paper's four primitives, as benches/track.rs keeps them.
PAPER = ("circles", "wave-h", "wave-v", "punch")

#: Each measure's target (issue 19).
STEP_SLOWER = 0.05
READ_SHARE = 0.80
READ_OVER_PURE = 20.0
BATCH_OVER_IDEAL = 1.3


def log(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def load() -> str:
    one, five, _ = os.getloadavg()
    return f"{one:.2f} (1 min), {five:.2f} (5 min)"


def subset_vocabulary(source: Path, out: Path, keep: Sequence[str]) -> List[str]:
    """Writes the primitives of `source` named in `keep` (in the file's own
    order) as a vocabulary file of its own: what benches/track.rs's
    `Vocabulary::retain` leaves of the shipped vocabulary, for both sides to
    load. The format is docs/formats.md's "Vocabulary files"; the package
    has no way to take a subset itself."""
    data = source.read_bytes()
    magic = b"imitate-vocab\n"
    if data[: len(magic)] != magic:
        raise SystemExit(f"{source}: not a vocabulary file")
    (version,) = struct.unpack_from("<I", data, 14)
    (length,) = struct.unpack_from("<Q", data, 18)
    header = json.loads(data[26 : 26 + length])
    offset = 26 + length + (8 - (26 + length) % 8) % 8
    arrays = {}
    for array in header["arrays"]:
        arrays[array["name"]] = data[offset : offset + 8 * array["len"]]
        offset += 8 * array["len"]
    names = [p["name"] for p in header["primitives"]]
    kept = [i for i, name in enumerate(names) if name in keep]
    if len(kept) != len(keep):
        raise SystemExit(f"{source}: has {names}, not all of {list(keep)}")
    listed, blobs = [], []
    for new, old in enumerate(kept):
        for array in header["arrays"]:
            prefix, _, field = array["name"].partition(".")
            if prefix == f"p{old}":
                listed.append({"len": array["len"], "name": f"p{new}.{field}"})
                blobs.append(arrays[array["name"]])
    header["primitives"] = [header["primitives"][i] for i in kept]
    header["arrays"] = listed
    header["data_bytes"] = sum(len(b) for b in blobs)
    text = json.dumps(header, sort_keys=True, separators=(",", ":"), ensure_ascii=False).encode()
    body = magic + struct.pack("<I", version) + struct.pack("<Q", len(text)) + text
    body += b"\0" * ((8 - len(body) % 8) % 8) + b"".join(blobs)
    out.write_bytes(body + struct.pack("<I", zlib.crc32(body)))
    return [names[i] for i in kept]


def criterion(args: argparse.Namespace, bench: str, group: str, name: str, env: Dict[str, str]) -> Dict[str, float]:
    """Runs one criterion benchmark and gives its median and mean
    estimates, seconds per iteration."""
    folder = args.target / "criterion" / group / name
    shutil.rmtree(folder, ignore_errors=True)
    command = ["cargo", "bench", "--quiet", "--bench", bench, "--", f"^{group}/{name}$"]
    log(f"$ {' '.join(f'{k}={v}' for k, v in env.items())} {' '.join(command)}")
    result = subprocess.run(command, cwd=args.repo, env={**os.environ, **env}, stdout=subprocess.PIPE, text=True)
    sys.stderr.write(result.stdout)
    if result.returncode != 0:
        raise SystemExit(f"cargo bench --bench {bench} failed")
    estimates = json.loads((folder / "new" / "estimates.json").read_text())
    return {k: estimates[k]["point_estimate"] * 1e-9 for k in ("median", "mean")}


# 1. Tracker.step


def step_python(frames: Path, vocab: Path, particles: int, seed: int, passes: int, winners: Path) -> Dict[str, Any]:
    masks = list(imitate.Silhouettes(str(frames)))
    vocabulary = imitate.Vocabulary.load(str(vocab))
    camera = imitate.Camera.from_json(str(frames.parent / "camera.json"))

    def fresh() -> imitate.Tracker:
        return imitate.Tracker(vocabulary, camera, particles=particles, feedback=True, seed=seed)

    tracker = fresh()
    ours = [tracker.step(silhouette=m).activity for m in masks]
    theirs = winners.read_text().split()
    differ = sum(a != b for a, b in zip(ours, theirs)) + abs(len(ours) - len(theirs))
    if differ:
        log(f"warning: Python's winners differ from Rust's in {differ} of {len(theirs)} frames")
    seconds = []
    for _ in range(passes):
        tracker = fresh()
        step = tracker.step
        started = time.perf_counter()
        for mask in masks:
            step(silhouette=mask)
        seconds.append(time.perf_counter() - started)
    return {
        "frames": len(masks),
        "primitives": len(vocabulary),
        "median": float(np.median(seconds)) / len(masks),
        "mean": float(np.mean(seconds)) / len(masks),
        "same_winners": not differ,
    }


def measure_step(args: argparse.Namespace) -> List[Dict[str, Any]]:
    four = args.work / "four.vocab"
    subset_vocabulary(args.shipped, four, PAPER)
    rows = []
    for name, vocab, particles in [("9x6", args.nine, 6), ("4x200", four, 200)]:
        winners = args.work / f"winners-{name}.txt"
        env = {
            "IMITATE_TRACK_FRAMES": str(args.frames.resolve()),
            "IMITATE_TRACK_VOCAB": str(vocab.resolve()),
            "IMITATE_TRACK_PARTICLES": str(particles),
            "IMITATE_TRACK_SEED": str(args.seed),
            "IMITATE_TRACK_NAME": name,
            "IMITATE_TRACK_WINNERS": str(winners.resolve()),
        }
        before = load()
        rust_pass = criterion(args, "track", "track_clip", name, env)
        log(f"Python: Tracker.step, {name}, {args.passes} passes")
        python = step_python(args.frames, vocab, particles, args.seed, args.passes, winners)
        rust = {k: v / python["frames"] for k, v in rust_pass.items()}
        slower = python["median"] / rust["median"] - 1
        frames = python["frames"]
        rows.append(
            {
                "measure": f"Tracker.step per frame, {python['primitives']} primitives × {particles} particles, "
                f"160×120 ({frames} frames a pass)",
                "rust": f"{rust['median'] * 1e3:.3f} ms (mean {rust['mean'] * 1e3:.3f})",
                "python": f"{python['median'] * 1e3:.3f} ms (mean {python['mean'] * 1e3:.3f})",
                "figure": f"{slower * 100:+.1f}% ({'same' if python['same_winners'] else 'DIFFERENT'} winners)",
                "target": f"≤ +{STEP_SLOWER * 100:.0f}%",
                "met": slower <= STEP_SLOWER,
                "load": f"{before} → {load()}",
            }
        )
    return rows


# 2. read_bvh + positions()


def read_python(files: Sequence[Path], passes: int) -> Dict[str, Any]:
    frames = 0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for path in files:
            frames += imitate.read_bvh(str(path)).positions().shape[0]
    seconds = []
    with warnings.catch_warnings():
        # Still issued (and paid for) from Rust, just not printed.
        warnings.simplefilter("ignore")
        for _ in range(passes):
            started = time.perf_counter()
            for path in files:
                imitate.read_bvh(str(path)).positions()
            seconds.append(time.perf_counter() - started)
    return {
        "frames": frames,
        "warnings": len(caught),
        "median": float(np.median(seconds)),
        "mean": float(np.mean(seconds)),
    }


def read_bvhio(files: Sequence[Path]) -> Dict[str, Any]:
    """bvhio (pure Python, on PyGLM) reading each file to the world position
    of every joint in every frame, as a frames × joints × 3 array."""
    import bvhio

    frames = 0
    started = time.perf_counter()
    for path in files:
        root = bvhio.readAsHierarchy(str(path))
        layout = root.layout()
        count = len(root.Keyframes)
        positions = np.empty((count, len(layout), 3))
        for f in range(count):
            root.loadPose(f, recursive=True)
            for j, (joint, _, _) in enumerate(layout):
                p = joint.PositionWorld
                positions[f, j] = (p.x, p.y, p.z)
        frames += count
    return {"frames": frames, "seconds": time.perf_counter() - started}


def measure_read(args: argparse.Namespace) -> List[Dict[str, Any]]:
    files = sorted(p for p in args.mocap.iterdir() if p.suffix.lower() == ".bvh")
    before = load()
    rust = criterion(args, "mocap", "read_folder", "positions", {"IMITATE_MOCAP_DIR": str(args.mocap.resolve())})
    log(f"Python: read_bvh + positions() over {len(files)} files, {args.passes} passes")
    python = read_python(files, args.passes)
    middle = load()
    log(f"bvhio: the same {len(files)} files to joint positions, once")
    pure = read_bvhio(files)
    frames = python["frames"]
    share = rust["median"] / python["median"]
    over = pure["seconds"] / python["median"]
    what = f"{len(files)} files, {frames} frames"
    return [
        {
            "measure": f"read_bvh + positions(), {args.mocap.name} ({what}) vs Rust",
            "rust": f"{rust['median']:.3f} s, {frames / rust['median']:,.0f} frames/s (mean {rust['mean']:.3f} s)",
            "python": f"{python['median']:.3f} s, {frames / python['median']:,.0f} frames/s "
            f"(mean {python['mean']:.3f} s)",
            "figure": f"{share * 100:.1f}% of Rust's speed",
            "target": f"≥ {READ_SHARE * 100:.0f}%",
            "met": share >= READ_SHARE,
            "load": f"{before} → {middle}",
        },
        {
            "measure": f"read_bvh + positions() vs bvhio {bvhio_version()}, same files",
            "rust": f"bvhio: {pure['seconds']:.1f} s ({pure['frames'] / pure['seconds']:,.0f} frames/s)",
            "python": f"{python['median']:.3f} s",
            "figure": f"{over:.0f}× faster",
            "target": f"≥ {READ_OVER_PURE:.0f}×",
            "met": over >= READ_OVER_PURE,
            "load": f"{middle} → {load()}",
        },
    ]


def bvhio_version() -> str:
    from importlib.metadata import version

    return version("bvhio")


# 3. imitate.batch track


def timed(command: Sequence[str], env: Optional[Dict[str, str]] = None) -> tuple[float, str]:
    started = time.perf_counter()
    result = subprocess.run(command, stderr=subprocess.PIPE, text=True, env=env)
    seconds = time.perf_counter() - started
    if result.returncode != 0:
        sys.stderr.write(result.stderr)
        raise SystemExit(f"failed ({result.returncode}): {' '.join(command)}")
    return seconds, result.stderr


def ray_cluster(work: Path, cpus: int) -> Dict[str, str]:
    """Starts a local Ray cluster of `cpus` CPUs, as a user's cluster is
    running before a batch is sent to it; the environment that points a
    command at it. `stop_ray` ends it."""
    ray = Path(sys.executable).parent / "ray"
    command = [str(ray), "start", "--head", f"--num-cpus={cpus}", "--include-dashboard=false"]
    command += ["--disable-usage-stats", f"--temp-dir={work / 'ray'}"]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return dict(os.environ, RAY_ADDRESS="auto")


def stop_ray() -> None:
    ray = Path(sys.executable).parent / "ray"
    subprocess.run([str(ray), "stop"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def measure_batch(args: argparse.Namespace) -> List[Dict[str, Any]]:
    clips = sorted(p for p in args.videos.iterdir() if p.suffix.lower() in (".avi", ".mp4", ".mkv", ".mov"))
    before = load()
    # Alone as a user runs it (every core), and on the one CPU and thread a
    # batch task has: a clip alone spreads its primitives' filters over
    # every core, so the ideal from the first is below what two
    # one-CPU workers can reach; the second is what they can.
    single: Dict[str, float] = {}
    one_cpu: Dict[str, float] = {}
    for clip in clips:
        out = args.work / "single" / clip.stem
        command = [str(args.imitate), "-q", "track", str(clip), "--vocab", str(args.shipped), "-o", str(out)]
        command += ["--camera", args.camera, "--force"]
        single[clip.stem], _ = timed(command)
        one_cpu[clip.stem], _ = timed(["taskset", "-c", "0", *command], dict(os.environ, RAYON_NUM_THREADS="1"))
        log(f"imitate track {clip.name}: {single[clip.stem]:.2f} s, {one_cpu[clip.stem]:.2f} s on one CPU")

    def ideal(times: Dict[str, float]) -> float:
        return max(max(times.values()), sum(times.values()) / 2)

    out = args.work / "batch"
    command = [sys.executable, "-m", "imitate.batch", "track", *map(str, clips), "--vocab", str(args.shipped)]
    command += ["-o", str(out), "--camera", args.camera, "--force"]
    env = ray_cluster(args.work, 2)
    try:
        log(f"$ RAY_ADDRESS=auto {' '.join(command)}")
        seconds, said = timed(command, env)
    finally:
        stop_ray()
    sys.stderr.write(said)
    inside = re.search(r"done in ([0-9.]+) s", said)
    same = all(
        (out / c.stem / "frames.csv").read_bytes() == (args.work / "single" / c.stem / "frames.csv").read_bytes()
        for c in clips
    )
    # The same batch with no cluster running: the command starts a local
    # one of 2 CPUs and stops it, which the figure above leaves out.
    cold = dict(os.environ)
    cold.pop("RAY_ADDRESS", None)
    log(f"$ {' '.join(command)} --workers 2")
    cold_seconds, _ = timed([*command, "--workers", "2"], cold)
    ratio = seconds / ideal(single)
    within = f"; {float(inside.group(1)):.1f} s from the first task to the last" if inside else ""
    return [
        {
            "measure": f"python -m imitate.batch track, {len(clips)} clips of {args.videos.name} (camera {args.camera}), "
            "a running local Ray cluster of 2 CPUs",
            "rust": f"ideal {ideal(single):.1f} s (alone: sum {sum(single.values()):.1f} s, slowest "
            f"{max(single.values()):.1f} s); on one CPU each: ideal {ideal(one_cpu):.1f} s",
            "python": f"{seconds:.1f} s, whole command{within}; {cold_seconds:.1f} s starting its own cluster",
            "figure": f"{ratio:.2f}× the ideal, {seconds / ideal(one_cpu):.2f}× the one-CPU ideal "
            f"({'same' if same else 'DIFFERENT'} frames.csv)",
            "target": f"≤ {BATCH_OVER_IDEAL}×",
            "met": ratio <= BATCH_OVER_IDEAL,
            "load": f"{before} → {load()}",
        }
    ]


def table(rows: Sequence[Dict[str, Any]]) -> str:
    lines = [
        "| measure | reference | Python package | figure | target | met | load average (start → end) |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        met = "yes" if r["met"] else "no"
        lines.append(
            f"| {r['measure']} | {r['rust']} | {r['python']} | {r['figure']} | {r['target']} | {met} | {r['load']} |"
        )
    return "\n".join(lines)


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repo", type=Path, required=True)
    parser.add_argument("--target", type=Path, required=True, help="cargo's target folder (criterion's results)")
    parser.add_argument("--imitate", type=Path, required=True, help="the release binary")
    parser.add_argument("--work", type=Path, default=Path.cwd())
    parser.add_argument("--nine", type=Path, required=True, help="a vocabulary of 9 primitives")
    parser.add_argument("--shipped", type=Path, required=True, help="the shipped vocabulary: its paper four for step, whole for batch")
    parser.add_argument("--frames", type=Path, required=True, help="a folder of 160×120 frames, camera.json beside it")
    parser.add_argument("--mocap", type=Path, required=True, help="a folder of BVH files")
    parser.add_argument("--videos", type=Path, required=True, help="a folder of clips")
    parser.add_argument(
        "--camera",
        default="side",
        help="batch's camera for every clip, alone and in the batch (side: kth_walking.avi has no frame an "
        "estimated camera can be found from)",
    )
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--passes", type=int, default=10, help="timed passes of each Python measure")
    parser.add_argument("--parts", default="step,read,batch")
    args = parser.parse_args(argv)
    parts = args.parts.split(",")
    log(f"imitate {imitate.__version__} from {Path(imitate.__file__).parent}; load average {load()}")
    rows: List[Dict[str, Any]] = []
    if "step" in parts:
        rows += measure_step(args)
    if "read" in parts:
        rows += measure_read(args)
    if "batch" in parts:
        rows += measure_batch(args)
    text = table(rows)
    (args.work / "python-bench.md").write_text(text + "\n")
    (args.work / "python-bench.json").write_text(json.dumps(rows, indent=2, ensure_ascii=False) + "\n")
    print(text)
    print(f"\n{os.cpu_count()} CPUs; load average at the end {load()}; table also in {args.work / 'python-bench.md'}")
    return 0 if all(r["met"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
