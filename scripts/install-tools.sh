#!/usr/bin/env bash
# Installs the programs imitate and its tests run as child processes, from
# Debian's packages: ffmpeg (with ffprobe) to decode video files, and
# chromium to open evaluation reports headless in the tests. Installs only
# what is missing, so it is safe to run again. Uses sudo only when not root.
#
#   bash scripts/install-tools.sh              # both
#   bash scripts/install-tools.sh ffmpeg       # one
set -euo pipefail

# package → the commands it must put on PATH
declare -A provides=([ffmpeg]="ffmpeg ffprobe" [chromium]="chromium")

wanted=("$@")
[ ${#wanted[@]} -eq 0 ] && wanted=(ffmpeg chromium)

missing=()
for package in "${wanted[@]}"; do
    [ -n "${provides[$package]:-}" ] || { echo "error: unknown tool '$package' (known: ${!provides[*]})" >&2; exit 2; }
    for command in ${provides[$package]}; do
        if ! command -v "$command" >/dev/null 2>&1; then
            missing+=("$package")
            break
        fi
    done
done

if [ ${#missing[@]} -eq 0 ]; then
    echo "already installed: ${wanted[*]}"
    exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
    echo "error: apt-get not found; install ${missing[*]} with your system's package manager" >&2
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
"${sudo[@]}" apt-get install -y --no-install-recommends "${missing[@]}"

# Check what was installed rather than trusting apt-get's exit code alone.
for package in "${missing[@]}"; do
    for command in ${provides[$package]}; do
        command -v "$command" >/dev/null 2>&1 || {
            echo "error: $command still not on PATH after installing $package" >&2
            exit 1
        }
    done
done
echo "installed: ${missing[*]}"
