#!/usr/bin/env bash
# Tracking the real clips (docs/numbers.md, "Real video"): every clip of
# ../shared/video/real (or $IMITATE_REAL_VIDEO) tracked with a vocabulary
# learned from ../shared/mocap/bandai, 6 particles, eq. 10, observing the
# silhouette, MediaPipe Pose's keypoints, or both; each scored by PCK@0.2
# against those keypoints (scripts/video-reference.sh, which installs
# mediapipe the first time). MediaPipe is a reference, not ground truth:
# the keypoints runs are scored against the points they were given.
#
#   bash scripts/real-video-trials.sh [WORK_DIR]        # about 3 minutes on 2 cores
source "$(dirname "$0")/common.sh" "$@"
clips="${IMITATE_REAL_VIDEO:-$(cd "$repo/.." && pwd)/shared/video/real}"
mocap="${IMITATE_MOCAP:-$(cd "$repo/.." && pwd)/shared/mocap}"
[ -d reference ] || IMITATE_REAL_VIDEO="$clips" bash "$repo/scripts/video-reference.sh" reference
"$imitate" -q vocab build "$mocap/bandai" --labels "$mocap/bandai/labels.csv" -o bandai.vocab

echo "| clip (label, camera) | PCK@0.2: silhouette / keypoints / both | most frames named (keypoints) | frames/s: silhouette / keypoints / both |"
echo "| --- | --- | --- | --- |"
tail -n +2 "$clips/labels.csv" | while IFS=, read -r file label camera _; do
    name="${file%.*}"
    for observe in silhouette keypoints both; do
        "$imitate" -q track "$clips/$file" --vocab bandai.vocab -o "runs/$name-$observe" --feedback --force \
            --keypoints "reference/$name/keypoints.csv" --observe "$observe"
        "$imitate" -q score "runs/$name-$observe" --keypoints "reference/$name/keypoints.csv"
    done
    python3 - "$name" "$label" "$camera" <<'PY'
import collections, csv, json, sys
name, label, camera = sys.argv[1:4]
runs = [f"runs/{name}-{o}" for o in ("silhouette", "keypoints", "both")]
pck = " / ".join(f"{json.load(open(r + '/agreement.json'))['pck_mirror']:.2f}" for r in runs)
rate = " / ".join(f"{json.load(open(r + '/summary.json'))['timing']['frames_per_second']:.0f}" for r in runs)
named = collections.Counter(row["activity"] or "(coasting)" for row in csv.DictReader(open(runs[1] + "/frames.csv")))
top = ", ".join(f"{a} {100 * n / sum(named.values()):.0f}%" for a, n in named.most_common(2))
print(f"| {name} ({label}, {camera}) | {pck} | {top} | {rate} |")
PY
done
