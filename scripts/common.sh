# Sourced by the trial scripts with their arguments: builds the release
# binary, sets $imitate (it), $repo and $vocab (vocab/default.vocab), and
# moves into the work folder, the first argument or else a new temporary one.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
repo="$PWD"
cargo build --release --quiet
imitate="${CARGO_TARGET_DIR:-$repo/target}/release/imitate"
vocab="$repo/vocab/default.vocab"
work="${1:-$(mktemp -d)}"
mkdir -p "$work"
cd "$work"
