#!/usr/bin/env bash
# The Python package's speed against the Rust library's, side by side in
# one run, with the targets of issue 19 ("Numbers to reach") beside each
# figure (docs/python.md, "Speed"):
#
# 1. `Tracker.step` from Python per frame of 160×120 silhouettes against the
#    Rust tracker's own loop, at 9 primitives × 6 particles (a vocabulary
#    learned here from `imitate synth`'s six activities with `--k 9`) and 4 ×
#    200 (the paper's four primitives of vocab/default.vocab, the ones
#    `cargo bench --bench track` keeps, written as a file of their own).
#    The frames are `imitate render` of a synthetic sequence of the six
#    activities. Rust reference: the `track_clip` group of benches/track.rs
#    (criterion; a fresh tracker stepped through the same decoded masks with
#    the same vocabulary file, camera and seed). Target: Python ≤ 5% slower.
# 2. `read_bvh(path).positions()` over every BVH of ../shared/mocap/bandai.
#    Rust reference: the `read_folder` group of benches/mocap.rs (the library
#    reading, retargeting and running forward kinematics on the same files,
#    one after the other, as Python's call does). Also bvhio, a pure-Python
#    reader, reading the same files to every joint's position in every frame
#    (PyMO, the other one the issue names, is not on PyPI). Targets: ≥ 80%
#    of the Rust speed, ≥ 20× bvhio's.
# 3. `python -m imitate.batch track` over the clips of ../shared/video/real
#    with vocab/default.vocab on a local Ray cluster of 2 workers, the whole
#    command timed, against the ideal: max(the slowest clip alone, the sum
#    over 2), each clip timed alone as an `imitate track` command in the same
#    run. Target: ≤ 1.3× the ideal.
#
# It installs what it needs into a virtual environment
# ($IMITATE_BENCH_VENV, default ~/.cache/imitate/py-bench-venv): numpy,
# pandas, ray, bvhio and the package itself (`pip install ./python`, built anew).
# Timing wants a quiet machine: the load average is printed with each row.
# Exit code 0 when every target is met, 1 when one is not.
#
#   bash scripts/python-bench.sh [WORK_DIR]     # about 10 minutes on 2 cores
#
# IMITATE_BENCH_PARTS=step,read,batch picks measures; IMITATE_BENCH_PASSES
# (10) is how many times each Python measure is timed; IMITATE_SHARED is the
# shared data folder (default: ../shared beside the repository).
source "$(dirname "$0")/common.sh" "$@"
venv="${IMITATE_BENCH_VENV:-$HOME/.cache/imitate/py-bench-venv}"
shared="${IMITATE_SHARED:-$(cd "$repo/.." && pwd)/shared}"
target="${CARGO_TARGET_DIR:-$repo/target}"

echo "load average at the start: $(cut -d' ' -f1-3 /proc/loadavg)" >&2
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
# pandas: `imitate.track` (what each batch task runs) returns a DataFrame.
"$venv/bin/python" -m pip install -q numpy pandas ray bvhio
# The package as the working tree has it: maturin builds it in cargo's target
# folder, so only what changed is compiled again.
"$venv/bin/python" -m pip install -q --force-reinstall --no-deps "$repo/python"
(cd "$repo" && cargo bench --quiet --no-run --bench track --bench mocap)

# 9 primitives: the six synthetic activities clustered into 9 (`fit` may
# split a cluster, so the k that gives nine is searched for downwards).
"$imitate" -q synth -o takes
for k in 9 8 7 6 5; do
    "$imitate" -q vocab build takes --labels takes/labels.csv --k "$k" -o nine.vocab
    count=$("$imitate" vocab info nine.vocab --json | "$venv/bin/python" -c 'import json, sys; print(len(json.load(sys.stdin)["primitives"]))')
    [ "$count" = 9 ] && break
done
[ "$count" = 9 ] || { echo "no k from 9 to 5 gives 9 primitives" >&2; exit 1; }
# 160×120 silhouettes (light noise) of the six activities in a row.
"$imitate" -q synth -o sequence --sequence circles,wave-h,wave-v,punch,reach,twist --reps 2
"$imitate" -q render sequence/sequence.bvh -o clip --size 160x120 --force

"$venv/bin/python" "$repo/scripts/python_bench.py" --repo "$repo" --target "$target" --imitate "$imitate" \
    --work "$PWD" --nine nine.vocab --shipped "$vocab" --frames clip/frames \
    --mocap "$shared/mocap/bandai" --videos "$shared/video/real" --parts "${IMITATE_BENCH_PARTS:-step,read,batch}" \
    --passes "${IMITATE_BENCH_PASSES:-10}"
