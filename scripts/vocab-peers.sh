#!/usr/bin/env bash
# The vocabulary's clustering beside scikit-learn's, on the same segments
# of three corpora: the demonstrator's four paper activities, the real
# captures of ../shared/mocap/real and Bandai's dataset 2
# (../shared/mocap/bandai). Installs scikit-learn into a virtual environment
# (under $HOME/.cache/imitate, or $IMITATE_PEERS_VENV) the first time;
# prints a Markdown table (docs/numbers.md keeps the last one).
#
#   bash scripts/vocab-peers.sh
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
venv="${IMITATE_PEERS_VENV:-$HOME/.cache/imitate/peers-venv}"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet --disable-pip-version-check scikit-learn==1.9.1 pandas==3.1.1
cargo build --release --quiet
bin="${CARGO_TARGET_DIR:-$root/target}/release/imitate"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
shared="$root/../shared/mocap"

# NAME LABELS INPUT...: segment, embed (writing the vectors) and cluster
# with the defaults, timed; then scikit-learn on the same vectors.
compare() {
    local name=$1 labels=$2
    shift 2
    local dir="$work/$name"
    mkdir -p "$dir"
    local started=$EPOCHREALTIME
    "$bin" segment "$@" --labels "$labels" -o "$dir/segments.csv" -q
    "$bin" embed "$dir/segments.csv" -o "$dir/embedding.csv" --vectors "$dir/vectors.csv" -q
    "$bin" cluster "$dir/embedding.csv" -o "$dir/clusters.csv" -q
    local ended=$EPOCHREALTIME
    "$venv/bin/python" scripts/peers/vocab_sklearn.py "$name" "$dir/vectors.csv" "$dir/clusters.csv" \
        "$started" "$ended"
}

echo "| corpus | learner | k | purity | adjusted Rand index | seconds |"
echo "| --- | --- | --- | --- | --- | --- |"
"$bin" synth -o "$work/synthetic" --activities circles,wave-h,wave-v,punch --reps 12 --seed 1 -q
compare synthetic "$work/synthetic/labels.csv" "$work/synthetic"
if [ -d "$shared/real" ]; then
    compare real "$shared/real/labels.csv" "$shared/real"
fi
if [ -d "$shared/bandai" ]; then
    compare bandai-dataset-2 "$shared/bandai/labels.csv" "$shared"/bandai/dataset-2_*.bvh
fi
