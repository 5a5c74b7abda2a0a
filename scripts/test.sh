#!/usr/bin/env bash
# The project's test command (the README's, and what .ci/run runs): installs
# the programs the tests drive when they are missing (ffmpeg to decode
# video, chromium to open reports headless; Debian packages, see
# install-tools.sh), then runs every test in the release profile. Extra
# arguments go to `cargo test`.
#
#   bash scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-tools.sh
cargo test --release "$@"
