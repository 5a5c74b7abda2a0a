"""Batch work on a Ray cluster, one task per clip or take::

    python -m imitate.batch track CLIPS... --vocab FILE.vocab -o DIR
    python -m imitate.batch segment TAKES... -o DIR

``track`` writes DIR/<clip>/ (the run folder ``imitate track`` writes),
``segment`` DIR/<take>.csv (the table ``imitate segment`` writes); each
result is what running that clip or take alone gives. The cluster is the
one ``ray.init()`` finds from the environment (``RAY_ADDRESS``, or
``--address``), else a local one of ``--workers`` CPUs. Each task asks for
``--cpus-per-task`` CPUs (1) and runs on that many threads, so tasks side
by side on one machine do not crowd one another. Each task's end is
reported as it comes, a failed one with its clip named and its error;
the others go on, and the exit code is 1 when any failed (2 for bad
arguments).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import imitate


def _track(clip: str, out: str, vocab: str, options: Dict[str, Any]) -> str:
    frames = imitate.track(clip, vocab, out=out, **options)
    return f"{len(frames)} frames → {out}"


def _segment(take: str, out: str, options: Dict[str, Any]) -> str:
    imitate.segment([take], out, **options)
    return f"→ {out}"


def _run(job: Callable[..., str], *args: Any) -> Tuple[bool, str]:
    """Runs one task; an error becomes its message, so one task's failure
    never stops the others."""
    try:
        return True, job(*args)
    except imitate.Error as e:
        return False, str(e)
    except Exception as e:  # noqa: BLE001 - any failure is reported with its clip
        return False, f"{type(e).__name__}: {e}"


def _names(paths: Sequence[str]) -> List[str]:
    """An output name per input: its file name without the extension, or
    its folder's name, made unique by its position when two coincide."""
    stems = []
    for p in paths:
        path = Path(p)
        stem = path.name if path.is_dir() else path.stem
        # A folder of frames called `frames` is named by the clip holding it.
        if stem == "frames" and path.is_dir():
            stem = path.parent.name
        stems.append(stem)
    return [s if stems.count(s) == 1 else f"{i:03}_{s}" for i, s in enumerate(stems)]


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m imitate.batch", description=__doc__.split("\n\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)

    def common(p: argparse.ArgumentParser) -> None:
        p.add_argument("-o", "--output", required=True, help="the folder results are written to")
        p.add_argument("--workers", type=int, help="CPUs of a local cluster (default: all)")
        p.add_argument("--address", help="a Ray cluster's address (default: RAY_ADDRESS, else a local cluster)")
        p.add_argument(
            "--cpus-per-task", type=int, default=1, help="CPUs each task asks for and threads it runs on (default: 1)"
        )

    track = commands.add_parser("track", help="track clips (folders of frames or videos)")
    track.add_argument("inputs", nargs="+", metavar="CLIP")
    track.add_argument("--vocab", required=True, help="the vocabulary (.vocab)")
    common(track)
    track.add_argument("--camera", help="a preset, a camera.json or auto (default: camera.json beside the frames)")
    track.add_argument("--particles", type=int)
    track.add_argument("--lookahead", type=int)
    track.add_argument("--seed", type=int)
    track.add_argument("--feedback", action="store_true", default=None)
    track.add_argument("--fps", type=float)
    track.add_argument("--height", type=float)
    track.add_argument("--work-size", type=int)
    track.add_argument("--keypoints-dir", help="a folder of keypoint files named as the clips (<clip>.csv)")
    track.add_argument("--force", action="store_true", help="replace output folders that hold something")

    segment = commands.add_parser("segment", help="segment BVH takes")
    segment.add_argument("inputs", nargs="+", metavar="TAKE")
    common(segment)
    segment.add_argument("--labels", help="activity labels (labels.csv)")
    segment.add_argument("--method", choices=["kcs", "zvc"])
    segment.add_argument("--min-length", type=float)
    segment.add_argument("--max-length", type=float)
    segment.add_argument("--up", choices=["y", "z"])
    segment.add_argument("--map", dest="mapping", help="a mapping file (MAPPING.toml)")
    return parser


def _options(args: argparse.Namespace, names: Sequence[str]) -> Dict[str, Any]:
    """The options given, as the package's keywords (those left out keep
    the library's defaults)."""
    return {n: getattr(args, n) for n in names if getattr(args, n, None) is not None}


def _tasks(args: argparse.Namespace) -> List[Tuple[str, Callable[..., str], Tuple[Any, ...]]]:
    out = Path(args.output)
    names = _names(args.inputs)
    if args.command == "track":
        options = _options(args, ["camera", "particles", "lookahead", "seed", "feedback", "fps", "height"])
        if args.work_size is not None:
            options["work_size"] = args.work_size
        tasks = []
        for clip, name in zip(args.inputs, names):
            each = dict(options, force=bool(args.force), threads=args.cpus_per_task)
            if args.keypoints_dir:
                each["keypoints"] = str(Path(args.keypoints_dir) / f"{name}.csv")
            tasks.append((clip, _track, (clip, str(out / name), args.vocab, each)))
        return tasks
    options = _options(args, ["labels", "method", "min_length", "max_length", "up", "mapping"])
    options["threads"] = args.cpus_per_task
    return [(take, _segment, (take, str(out / f"{name}.csv"), options)) for take, name in zip(args.inputs, names)]


def _connect(args: argparse.Namespace) -> Any:
    import ray

    address = args.address or os.environ.get("RAY_ADDRESS")
    if address:
        ray.init(address=address, log_to_driver=False)
    else:
        ray.init(num_cpus=args.workers, log_to_driver=False, include_dashboard=False)
    return ray


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if args.cpus_per_task < 1:
        parser.error("--cpus-per-task: must be at least 1")
    try:
        ray = _connect(args)
    except ImportError:
        print("imitate.batch: error: Ray is not installed (pip install ray)", file=sys.stderr)
        return 2
    Path(args.output).mkdir(parents=True, exist_ok=True)
    tasks = _tasks(args)
    remote = ray.remote(num_cpus=args.cpus_per_task)(_run)
    pending = {remote.remote(job, *job_args): name for name, job, job_args in tasks}
    started, failed, done = time.monotonic(), 0, 0
    while pending:
        ready, _ = ray.wait(list(pending), num_returns=1)
        name = pending.pop(ready[0])
        try:
            ok, text = ray.get(ready[0])
        except Exception as e:  # noqa: BLE001 - a worker that died is that task's failure
            ok, text = False, f"{type(e).__name__}: {e}"
        done += 1
        failed += not ok
        status = text if ok else f"error: {text}"
        print(f"[{done}/{len(tasks)}] {name}: {status}", file=sys.stderr, flush=True)
    seconds = time.monotonic() - started
    print(f"{len(tasks) - failed} of {len(tasks)} done in {seconds:.1f} s; {failed} failed", file=sys.stderr)
    ray.shutdown()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
