#!/usr/bin/env bash
# Speed on real video (docs/numbers.md, "Real video"): one command from a
# video file to frames.csv (decoding, the learned background, silhouettes at
# the default working size, the shipped vocabulary's 10 primitives × 6
# particles, eq. 10), timed from start to exit, beside MediaPipe Pose's
# frames a second on the same clip (mediapipe 0.10.21, model complexity 1,
# segmentation on; its own timing of the model alone, decoding left out).
# Every clip of ../shared/video/real (or $IMITATE_REAL_VIDEO) is timed; the
# first run installs mediapipe into a virtual environment
# (scripts/keypoints.sh).
#
#   bash scripts/video-speed.sh [WORK_DIR]        # about 2 minutes on 2 cores
source "$(dirname "$0")/common.sh" "$@"
clips="${IMITATE_REAL_VIDEO:-$(cd "$repo/.." && pwd)/shared/video/real}"
echo "| clip | size | frames | imitate: whole command (frames/s) | MediaPipe Pose: model alone (frames/s) |"
echo "| --- | --- | --- | --- | --- |"
tail -n +2 "$clips/labels.csv" | while IFS=, read -r file _; do
    name="${file%.*}"
    started=$(date +%s.%N)
    # A clip the tracker refuses (it says why) is a row, not the end.
    if ! "$imitate" -q track "$clips/$file" --vocab "$vocab" -o "speed-$name" --force --feedback; then
        echo "| $name | | | not tracked | |"
        continue
    fi
    ended=$(date +%s.%N)
    mediapipe=$(bash "$repo/scripts/keypoints.sh" "$clips/$file" "speed-$name.csv" 2>/dev/null | sed -n 's/.* at \([0-9.]*\) frames\/s.*/\1/p')
    python3 - "$name" "$started" "$ended" "speed-$name/summary.json" "$mediapipe" <<'PY'
import json, sys
name, started, ended, summary, mediapipe = sys.argv[1:6]
s = json.load(open(summary))
size = "×".join(str(v) for v in (s["camera"]["width"], s["camera"]["height"]))
rate = s["frames"] / (float(ended) - float(started))
print(f"| {name} | {size} | {s['frames']} | {rate:.0f} | {float(mediapipe):.0f} |")
PY
done
