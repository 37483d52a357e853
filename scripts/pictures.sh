#!/usr/bin/env bash
# The pictures of the game in the README and the guide, made again from the current build:
# the animated round and the screenshots under each policy. They are rendered in a real window
# under a virtual X server with Mesa's software Vulkan driver (minutes, not seconds).
# Needs: apt-get install -y xvfb mesa-vulkan-drivers libvulkan1
# Usage: scripts/pictures.sh [OUT_DIR]     (default: docs)
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/simlod/target}"
out="${1:-docs}"
mkdir -p "$out"
cargo build --release
play() {
    xvfb-run -a -s "-screen 0 1280x720x24" "$CARGO_TARGET_DIR/release/simlod" play "$@"
}
# Six seconds of the default game (combined policy): levels change as the puck comes near.
play --record "$out/round.gif" --frames 180
play --screenshot "$out/screenshot.png" --frames 120
play --policy all-rigid --screenshot "$out/screenshot-rigid.png" --frames 120
play --policy camera --screenshot "$out/screenshot-camera.png" --frames 120
play --policy budget --frame-budget 1 --screenshot "$out/screenshot-budget.png" --frames 120
# The crowd: 3,000 creatures, a second and a half a frame in software.
play --scenario scenarios/crowd.ron --screenshot "$out/crowd.png" --frames 40
ls -l "$out"/round.gif "$out"/screenshot*.png "$out"/crowd.png
