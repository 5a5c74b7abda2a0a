#!/usr/bin/env bash
# The reference for the real clips (docs/numbers.md, "Real video"):
# MediaPipe Pose (mediapipe 0.10.21, model complexity 1, segmentation on)
# run on every clip of ../shared/video/real (or $IMITATE_REAL_VIDEO),
# writing OUT_DIR/CLIP/keypoints.csv (the layout `track --keypoints` reads)
# and OUT_DIR/CLIP/masks/NNNNNN.png (its person masks), and printing
# MediaPipe's frames a second on each. It is a reference, not ground
# truth. Installs mediapipe into a virtual environment the first time
# (scripts/keypoints.sh).
#
#   bash scripts/video-reference.sh OUT_DIR        # about 1 minute on 2 cores
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
clips="${IMITATE_REAL_VIDEO:-$(cd "$here/../.." && pwd)/shared/video/real}"
out="${1:?usage: bash scripts/video-reference.sh OUT_DIR}"
if [ ! -f "$clips/labels.csv" ]; then
    echo "$clips: no labels.csv; set IMITATE_REAL_VIDEO to the folder of real clips" >&2
    exit 1
fi
mkdir -p "$out"
tail -n +2 "$clips/labels.csv" | while IFS=, read -r file _; do
    name="${file%.*}"
    rm -rf "$out/$name"
    mkdir -p "$out/$name"
    bash "$here/keypoints.sh" "$clips/$file" "$out/$name/keypoints.csv" --masks "$out/$name/masks" 2>/dev/null
done
