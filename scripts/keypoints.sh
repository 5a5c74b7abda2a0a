#!/usr/bin/env bash
# 2-D keypoints of a video from MediaPipe Pose, for `imitate track
# --keypoints` (docs/formats.md, "Keypoints"). Installs mediapipe==0.10.21,
# which ships its models, into a virtual environment (under
# $HOME/.cache/imitate, or $IMITATE_MEDIAPIPE_VENV) the first time.
#
#   bash scripts/keypoints.sh VIDEO OUT.csv|OUT.json [--masks DIR]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="${IMITATE_MEDIAPIPE_VENV:-$HOME/.cache/imitate/mediapipe-venv}"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
if ! "$venv/bin/python" -c "import mediapipe" 2>/dev/null; then
    "$venv/bin/pip" install --quiet --disable-pip-version-check mediapipe==0.10.21
fi
exec "$venv/bin/python" "$here/keypoints.py" "$@"
