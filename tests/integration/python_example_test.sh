#!/usr/bin/env bash
# examples/follow_tags.py against wirc-sim, from the build tree: Debian's
# Python with python3-gi reads the tags through the Wirc typelib.
#   python_example_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$(realpath "$1")
source=$(realpath "$2")
log=$(mktemp)
"$build/bin/wirc-sim" --port 0 --duration 60 >"$log" 2>&1 &
sim=$!
trap 'kill $sim 2>/dev/null || true; rm -f "$log"' EXIT
for _ in $(seq 100); do grep -q "listening on" "$log" && break; sleep 0.05; done
port=$(sed -n 's/^wirc-sim: listening on 127.0.0.1:\([0-9]*\)$/\1/p' "$log")
[[ -n "$port" ]] || { echo "wirc-sim did not start: $(cat "$log")" >&2; exit 1; }
output=$(GST_PLUGIN_PATH="$build/gst-plugins" GST_REGISTRY="$build/python-example-registry.bin" \
  GI_TYPELIB_PATH="$build/lib/girepository-1.0" LD_LIBRARY_PATH="$build/lib" \
  /usr/bin/python3 "$source/examples/follow_tags.py" --port "$port" --frames 10 \
  --tag-size 0.16 --fx 304.8)
echo "$output"
# The simulator's target carries tag 0 of tag36h11 about 1.2 m ahead.
tags=$(grep -cE '^frame [0-9]+: tag 0 \(tag36h11\) at [0-9.]+,[0-9.]+ corners( [0-9.]+,[0-9.]+){4} pose .* z=1\.[0-9]+ m$' <<<"$output")
(( tags >= 8 )) || { echo "only $tags of 10 frames had the tag" >&2; exit 1; }
