#!/usr/bin/env bash
# Tracking the real clips (docs/numbers.md, "Real video"): MediaPipe Pose's
# masks and landmarks of every clip of ../shared/video/real (or
# $IMITATE_REAL_VIDEO) made once by scripts/video-reference.sh (which
# installs mediapipe 0.10.21 into a virtual environment the first time),
# then `imitate eval --quick --real-video` with them: each clip tracked
# with a vocabulary of all of ../shared/mocap (or $IMITATE_MOCAP), 6
# particles, eq. 10, observing the silhouette, the keypoints or both. Prints
# the report's real_video table; the report is WORK_DIR/report.
# MediaPipe is a reference, not ground truth.
#
#   bash scripts/real-video-trials.sh [WORK_DIR]        # about 8 minutes on 2 cores
source "$(dirname "$0")/common.sh" "$@"
clips="${IMITATE_REAL_VIDEO:-$(cd "$repo/.." && pwd)/shared/video/real}"
mocap="${IMITATE_MOCAP:-$(cd "$repo/.." && pwd)/shared/mocap}"
[ -d reference ] || IMITATE_REAL_VIDEO="$clips" bash "$repo/scripts/video-reference.sh" reference
"$imitate" -q eval -o report --quick --force --mocap "$mocap" --real-video "$clips" --video-reference reference
cat report/real_video.csv
