#!/usr/bin/env bash
# Installs ffmpeg and ffprobe (Debian's `ffmpeg` package), which `imitate`
# runs as child processes to decode video files. Does nothing when both are
# already on PATH, so it is safe to run again. Uses sudo only when not root.
#
#   bash scripts/install-ffmpeg.sh
set -euo pipefail

if command -v ffmpeg >/dev/null 2>&1 && command -v ffprobe >/dev/null 2>&1; then
    echo "ffmpeg is already installed: $(command -v ffmpeg)"
    exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
    echo "error: apt-get not found; install ffmpeg (with ffprobe) with your system's package manager" >&2
    exit 1
fi

if [ "$(id -u)" -eq 0 ]; then
    sudo=()
elif command -v sudo >/dev/null 2>&1; then
    sudo=(sudo)
else
    echo "error: not root and sudo not found; run this script as root" >&2
    exit 1
fi

export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update
"${sudo[@]}" apt-get install -y --no-install-recommends ffmpeg

# Check what was installed rather than trusting apt-get's exit code alone.
command -v ffmpeg >/dev/null 2>&1 && command -v ffprobe >/dev/null 2>&1 || {
    echo "error: ffmpeg or ffprobe still not on PATH after installing" >&2
    exit 1
}
echo "installed: $(ffmpeg -version | head -n 1)"
