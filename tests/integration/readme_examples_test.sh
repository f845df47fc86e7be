#!/usr/bin/env bash
# Runs the README's quick-start block verbatim (it starts wirc-sim on
# 127.0.0.1:1984 itself), in a scratch folder, and checks what it made.
#   readme_examples_test.sh README.md BUILD_DIR
set -euo pipefail
readme=$(realpath "$1")
build=$(realpath "$2")
work=$(mktemp -d)
group=""
cleanup() {
  [[ -n "$group" ]] && kill -- "-$group" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

awk '/<!-- readme-examples/ { found = 1; next }
     found && /^```sh/ { inside = 1; next }
     inside && /^```/ { exit }
     inside' "$readme" >"$work/examples.sh"
[[ -s "$work/examples.sh" ]] || { echo "no readme-examples block in $readme" >&2; exit 1; }

ln -s "$build" "$work/build"
cd "$work"
export GST_REGISTRY="$work/registry.bin"
# A process group of its own, so the examples' background jobs end with it.
setsid bash -euo pipefail -x examples.sh &
group=$!
wait "$group"

[[ -s drive.mkv ]] || { echo "drive.mkv was not written" >&2; exit 1; }
[[ -s frames.mjpeg ]] || { echo "frames.mjpeg was not written" >&2; exit 1; }
echo "README examples ran: $(stat -c %s drive.mkv) bytes of video, $(stat -c %s frames.mjpeg) bytes of frames"
